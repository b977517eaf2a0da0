#pragma once
// The order queue of one logical agent (no DDS): orders are validated against the topology
// when they arrive, executed one at a time in arrival order, each destination in turn, may
// be withdrawn, and every change of an order is reported to an observer (the agent
// publishes it).

#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"
#include "drover/topology/model.hpp"

namespace drover::logical_agent {

/// One stop of an order: a vertex and what to do there.
struct Destination {
  topology::EntityIndex location = topology::kNoEntity;
  std::string location_id;
  std::string operation;  ///< "NOP"/empty, "park", "load", "unload", "charge" or a custom name
  std::map<std::string, std::string> properties;
};

enum class OrderState { queued, running, finished, failed, withdrawn };
const char* to_string(OrderState state) noexcept;
/// Whether an order in `state` has not ended (queued or running).
constexpr bool is_open(OrderState state) noexcept {
  return state == OrderState::queued || state == OrderState::running;
}

struct Order {
  std::string name;
  std::vector<Destination> destinations;
  std::map<std::string, std::string> properties;
  OrderState state = OrderState::queued;
  std::size_t destination = 0;  ///< index of the destination being executed
  TimeNs created = 0;
  std::optional<TimeNs> started;
  std::optional<TimeNs> finished;
  std::string failure;  ///< failed: why; withdrawn: the reason given
  /// Running, to be withdrawn (the executor ends it once the vehicle stands): the reason.
  std::optional<std::string> withdrawal;
  /// Running: the RAN command of the current destination's operation, once commanded, so
  /// that an agent restarted meanwhile looks for its outcome instead of doing it again.
  std::optional<std::string> action_command;
};

/// The RAN action an operation asks for at its location; nullopt when it asks for none
/// ("NOP", empty, "park": the vehicle only drives there).
std::optional<ran::ActionCommand> operation_action(const Destination& destination);

/// An order as requested: name and destinations by vertex id.
struct OrderSpec {
  std::string name;
  struct Stop {
    std::string location;
    std::string operation;
    std::map<std::string, std::string> properties;
  };
  std::vector<Stop> destinations;
  std::map<std::string, std::string> properties;
};

/// Checks a requested order against the topology.
/// \return the order (queued, not yet timed), or invalid_argument naming the problem: an
///         empty name, no destination, a location (by destination index) that is not a
///         vertex of the topology.
Result<Order> make_order(const topology::Topology& topology, const OrderSpec& spec);

/// Checks that the vehicle performs every action `order` asks for at its destinations from
/// index `from` on, as its RAN advertises them (`status.actions`; when it advertises none,
/// every action passes and the RAN decides).
/// \return invalid_argument naming the destination, the operation and what the vehicle
///         performs.
Status check_operations(const Order& order, const ran::VehicleStatus& status, std::size_t from = 0);

/// Not thread-safe: the agent guards it with its mutex.
class OrderBook {
 public:
  /// Called with the order after every change (queued, started, advanced, ended).
  using Observer = std::function<void(const Order&)>;
  /// Stores the order durably after every change, before the observer hears of it
  /// (`added`: a new order), including those the observer is not told of (a withdrawal
  /// marked, an action commanded). A failure refuses a new order (add returns it, nothing
  /// is queued) and is returned by action_commanded; after any other change the book goes
  /// on, since the vehicle's work must not stop for a full disk: the recorder deals with
  /// it (a queued order withdrawn meanwhile may then run after a restart).
  using Recorder = std::function<Status(const Order&, bool added)>;
  /// Called with the name of an ended order the book forgets (see ended_kept), once the
  /// observer heard of it: what was published of it can go too.
  using Forgetter = std::function<void(const std::string& name)>;
  /// What the book tells of its changes; each may be empty.
  struct Hooks {
    Observer changed = {};
    Recorder record = {};
    Forgetter forgotten = {};
  };
  /// How many ended orders are kept for lookups (name conflicts, late withdrawals) by default.
  static constexpr std::size_t kEndedKept = 1000;

  /// \param ended_kept  ended orders kept, the oldest forgotten first (an agent runs for
  ///                    months: its book must not grow with every order it ever ran); a
  ///                    forgotten order's name may be used again
  explicit OrderBook(Hooks hooks, std::size_t ended_kept = kEndedKept)
      : hooks_(std::move(hooks)), ended_kept_(ended_kept) {}

  /// Fills an empty book with orders an earlier life of the agent stored, oldest first (at
  /// most one running), and tells the observer of each (not the recorder: they are stored).
  /// The oldest ended ones beyond ended_kept are left out first (unpublished, so the
  /// forgetter is not told of them).
  void restore(std::vector<Order> orders);

  /// Queues `order` at `now`. \return its 1-based position among the unfinished orders,
  ///         conflict when an order of that name is known, or the recorder's error
  ///         (nothing changes on error).
  Result<std::size_t> add(Order order, TimeNs now);

  /// The order being executed, if any.
  const Order* current() const;
  /// Starts the oldest queued order at `now` when none runs. \return the running order.
  const Order* start_next(TimeNs now);
  /// The running order's operation at its current destination is commanded to the RAN as
  /// `command` (recorded, not published: its progress is the same). \return the
  /// recorder's error: then the command must not be sent (a restart would not know of it
  /// and could do the operation twice).
  Status action_commanded(const std::string& command);
  /// The running order's current destination is done: moves to the next one.
  /// \return true when the order has more destinations; false when it finished (at `now`).
  bool advance(TimeNs now);
  /// Fails the running order with `reason` at `now` (no-op when none runs).
  void fail_current(const std::string& reason, TimeNs now);

  /// Withdraws order `name` for `reason`: a queued one ends withdrawn at `now`; a running
  /// one is only marked (its `withdrawal` set, nothing published), and the executor ends it
  /// with end_withdrawn once the vehicle stands. Withdrawing a running order again is no
  /// change. \return the order's state after the call; not_found when no order has that
  /// name, conflict when it has ended (nothing changes on error).
  Result<OrderState> withdraw(const std::string& name, const std::string& reason, TimeNs now);
  /// Whether the running order is to be withdrawn.
  bool withdrawal_pending() const;
  /// Ends the running order as withdrawn at `now` (no-op when none runs).
  void end_withdrawn(TimeNs now);

  /// Orders waiting behind the running one.
  std::size_t queued_count() const;
  const Order* find(const std::string& name) const;

 private:
  Order* running();
  void publish(const Order& order) const {
    if (hooks_.changed) hooks_.changed(order);
  }
  Status record(const Order& order, bool added = false) const {
    return hooks_.record ? hooks_.record(order, added) : Status{};
  }
  /// Records, then publishes, a change of a known order.
  void changed(const Order& order) const {
    (void)record(order);  // failures are the recorder's to report (see Recorder)
    publish(order);
  }
  /// Forgets the oldest ended orders beyond ended_kept_ (only from the front: pointers to
  /// the others, current(), stay valid), telling the forgetter when `published`.
  void forget_oldest_ended(bool published = true);
  /// Records and publishes `order`, which has just ended, then forgets the oldest ended
  /// orders beyond ended_kept_, `order` itself possibly (not to be read afterwards).
  void publish_ended(const Order& order);

  Hooks hooks_;
  std::size_t ended_kept_;
  std::size_t ended_ = 0;     ///< ended orders in orders_
  std::deque<Order> orders_;  ///< in arrival order; ended ones stay for lookups (see ended_kept_)
};

}  // namespace drover::logical_agent

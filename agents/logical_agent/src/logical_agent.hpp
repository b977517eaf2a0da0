#pragma once
// The logical agent of one vehicle (docs/logical-agent.md): serves the order service,
// executes orders one at a time (per destination a real route from a routing agent,
// allocation ahead of the vehicle in route order, move commands to the RAN up to the last
// allocated vertex, the operation), watches the RAN's footprint and time windows, releases
// what the vehicle has left, propagates and follows delays, re-plans around locks, handles
// RAN errors, parks and charges when idle, and publishes order progress, vehicle state and
// operator alarms.
//
// Threads: DDS callbacks only record what arrived (orders, notices, statuses) and wake the
// executor; one executor thread does everything else, so the driving logic is sequential.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "agents/logical_agent/src/command_watch.hpp"
#include "agents/logical_agent/src/footprint_monitor.hpp"
#include "agents/logical_agent/src/late_grants.hpp"
#include "agents/logical_agent/src/order_book.hpp"
#include "agents/logical_agent/src/order_journal.hpp"
#include "agents/logical_agent/src/route_tracker.hpp"
#include "agents/logical_agent/src/topology_services.hpp"
#include "drover/carp/vehicle.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/writer.hpp"
#include "drover/logical_agent/charging.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/ran_runner/client.hpp"

namespace drover::logical_agent {

struct LogicalAgentOptions {
  /// DDS settings; participant.agent_id is the vehicle id.
  dds::ParticipantOptions participant;
  /// The RAN's agent id; empty: ran-<vehicle id>.
  std::string ran_agent;
  /// The vehicle, for routes and travel-time estimates (id and type included).
  carp::VehicleProfile vehicle;
  /// How many vertices ahead of the vehicle are allocated (>= 1).
  std::size_t lookahead = 2;
  /// A delay is propagated once the vehicle will reach its next vertex this much later
  /// than planned; it is propagated as the estimated lateness plus this margin again.
  DurationNs delay_threshold = seconds_to_ns(2);
  /// Idle this long (shared clock) → drive to a free parking vertex; < 0: never.
  DurationNs park_after = seconds_to_ns(30);
  /// Below this state of charge the vehicle charges before new work; <= 0: never.
  double charge_below = kDefaultChargeBelow;
  /// The state of charge a charge action aims at (above charge_below: see charging_problem).
  double charge_to = kDefaultChargeTo;
  /// A recoverable RAN error (stall, protective field, lost RAN) lasting longer fails the
  /// order with an alarm.
  DurationNs error_limit = seconds_to_ns(60);
  /// How long no route may be found (locks, full timelines) before the order fails.
  DurationNs route_limit = seconds_to_ns(120);
  /// Waiting this long (shared clock) for one allocation tells the operator (an
  /// ALARM_WARNING, once per wait); 0: never.
  DurationNs wait_alarm = seconds_to_ns(60);
  /// Real-time period of the executor's checks when nothing arrives.
  std::chrono::milliseconds tick{50};
  /// Real-time timeouts: topology calls, route calls, one allocation wait.
  std::chrono::milliseconds call_timeout{3000};
  std::chrono::milliseconds route_timeout{10000};
  std::chrono::milliseconds allocate_wait{300};
  /// The order journal (docs/logical-agent.md "Persistence"): the orders an earlier life
  /// stored are restored on start, and every change is stored before it is acknowledged or
  /// published. Empty: none (orders do not survive a restart).
  std::filesystem::path order_journal;
};

/// Serves from create() until destroyed.
class LogicalAgent {
 public:
  /// \return the agent (its executor started), or invalid_argument (bad vehicle profile,
  ///         lookahead 0, charging thresholds charging_problem refuses), the order journal's
  ///         errors (OrderJournal::open, load), or the DDS layer's errors.
  static Result<std::unique_ptr<LogicalAgent>> create(std::shared_ptr<const topology::Topology> topology,
                                                      SharedClock clock, LogicalAgentOptions options);
  /// Stops the executor (cancelling the current route's future reservations), then the
  /// DDS entities.
  ~LogicalAgent();
  LogicalAgent(const LogicalAgent&) = delete;
  LogicalAgent& operator=(const LogicalAgent&) = delete;

  const std::string& vehicle_id() const noexcept { return participant_->agent_id(); }

 private:
  enum class Activity { idle, driving, operating, parking, charging, waiting, error, paused };
  /// How following a route ended (withdrawn: the running order is being withdrawn, paused:
  /// an operator paused the vehicle; either way it stands where its commanded moves took it).
  enum class FollowResult { arrived, replan, failed, withdrawn, paused };

  LogicalAgent(std::shared_ptr<const topology::Topology> topology, SharedClock clock, LogicalAgentOptions options,
               std::optional<OrderJournal> journal);
  Status start();

  // ---- the order journal (restore in take_over.cpp, record in logical_agent.cpp) ----
  /// Before the executor and the services start: fills the book with the orders an earlier
  /// life stored (publishing their progress). An unfinished order with a destination that
  /// is no longer a vertex of the topology fails. A running order's action the earlier life
  /// commanded is adopted: its outcome is awaited (resume_action), not commanded again.
  void restore_orders(std::vector<Order> orders);
  /// The book's recorder: stores `order` in the journal. A failure raises an ALARM_CRITICAL
  /// (once until the journal is written again) and keeps the order to be stored again with
  /// the next change. \pre mutex_ is held (the book calls it)
  Status record_order(const Order& order, bool added);

  /// Reader options for an event topic, keeping only samples whose `field` is this vehicle.
  dds::ReaderOptions events_naming_this_vehicle(const std::string& field) const;

  // ---- DDS callbacks (record and wake) ----
  void on_order(const msg::OrderRequest& request, dds::ReplyHandle<msg::OrderReply> reply);
  void on_withdraw(const msg::OrderWithdrawRequest& request, dds::ReplyHandle<msg::OrderWithdrawReply> reply);
  /// An operator pauses or resumes the vehicle (stored in the journal first, if any).
  void on_pause(const msg::VehiclePauseRequest& request, dds::ReplyHandle<msg::StatusReply> reply);
  void on_notice(const msg::ReservationNotice& notice);
  void on_make_way(const msg::MakeWayRequest& request);
  void on_status(const ran::VehicleStatus& status);
  void publish_progress(const Order& order);
  /// Ends the published progress of an order the book forgot: late joiners (droverctl
  /// orders) no longer get it, and the writer's history does not grow with every order.
  void retire_progress(const std::string& name);

  // ---- executor ----
  void run();
  /// Waits for an event or the tick. \return false when stopping.
  bool wait_event();
  std::optional<ran::VehicleStatus> latest_status();
  /// The latest status when it is recent and shows the vehicle still, else nullopt.
  std::optional<ran::VehicleStatus> recent_standing_status();
  // ---- taking over from an earlier life (take_over.cpp) ----
  /// Once, before anything else: asks the topology agents what an earlier life of this
  /// agent (one that crashed or was killed) left there. What it holds becomes this life's
  /// (leftovers of an earlier route: hold_position swaps the vertex under the vehicle onto
  /// its hold and releases the rest once the footprint leaves it); every route it left is
  /// cancelled but for those allocations, so that nobody waits behind a route no one drives.
  /// Waits a few seconds at most for the topology agents (the vehicle is not protected by a
  /// hold until then): a partition that did not answer is left to take_over_late.
  /// \return false only when stopping before the topology agents answered.
  bool take_over();
  /// Makes what an earlier life left this life's: the entities it holds become leftovers
  /// (released once the footprint leaves them), and its routes are cancelled but for those
  /// (in `partitions`; empty: every partition).
  void adopt_leftovers(const Holdings& left, const std::vector<std::string>& partitions);
  /// The rest of take_over, for the partitions whose owner did not answer it: tried at most
  /// once a second while one of them has a live owner. What the earlier life left there
  /// (the hold of a station in a partition whose topology agent restarted from its
  /// journal, say) is adopted as take_over does, but for this life's own routes.
  /// \return whether `partition` (when given) is known now.
  bool take_over_late(const std::string& partition = {});
  /// Whether commands this life did not give (an earlier life's moves) still run on the
  /// RAN, or the vehicle still moves after them: they end on what that life allocated,
  /// which this life holds, so they are let run (a cancel would leave the vehicle part-way
  /// along an edge) for error_limit at most, then cancelled.
  bool earlier_commands_running(const ran::VehicleStatus& status);

  /// Finds the vertex the vehicle stands on and holds it with a route to itself (once a
  /// recent status shows it standing, after cancelling moves the RAN may still run), then
  /// releases what earlier routes left allocated that the vehicle does not need.
  /// Where that vertex cannot be held (another vehicle is due there next, or it is locked):
  /// see stranded_on. A vehicle that stands part-way along an edge: see finish_edge.
  /// \return whether it holds one now.
  bool hold_position();
  /// A vehicle stopped part-way along an edge it holds (a cancel after its moves failed or
  /// were lost), inside what it holds, with no RAN error (warnings aside), not paused and
  /// not stopped by a critical alarm since it last held a vertex, drives on to the end of the
  /// edge it was heading for (the edge's `to` when one-way), once that vertex is reserved
  /// and allocated to it: it then stands on a vertex again and works on. Tried at most every
  /// kClearWayRetry. \return whether the vehicle holds that vertex now.
  bool finish_edge(const ran::VehicleStatus& status);
  /// The vehicle stands on `vertex` and the routing agent refuses a hold of it (no_window,
  /// locked: `why`): it keeps the vertex reserved
  /// ahead of now (keep_standing_reserved), so that the vehicles due there wait behind it
  /// and none is given the vertex under it, tells the operator once (a warning), and now
  /// and then tries to clear the way to a parking vertex. Pauses before returning, so that
  /// the executor asks the routing agent a few times a second at most.
  /// \return whether the vehicle holds a vertex now (it cleared the way).
  bool stranded_on(topology::EntityIndex vertex, const std::string& why);
  /// While the vehicle stands on `vertex` under a route step with a bounded window (it
  /// waits for a route there, or cannot hold it), that window must not run out: the next
  /// vehicle due there would be planned onto the vertex under it, and this vehicle could
  /// plan no route from it. Once the window would end within `ahead` / 2, it is delayed at
  /// the vertex's owner (I3: those due after it move back in order) to end `ahead` from
  /// now; the rest of that route is cancelled by then. Nothing for an open-ended hold, or a
  /// vertex not held under a known route.
  void keep_standing_reserved(topology::EntityIndex vertex, DurationNs ahead);
  std::optional<topology::EntityIndex> vertex_under(const ran::VehicleStatus& status) const;
  /// A real route from the vehicle's vertex to `goal`, retried (within route_limit) while
  /// it is blocked. \return the route or why none.
  /// \param patience  how long (shared clock) to keep trying while the timelines or locks
  ///                  leave no route; 0: one try.
  /// \param for_order  the route serves the running order: waiting for one ends (an error)
  ///                  once the order is being withdrawn.
  /// \param refusal    when given and the routing agent refused the route, set to its
  ///                  failure name (no_window, locked, conflict, ...); otherwise cleared.
  Result<RouteTracker> plan_route(topology::EntityIndex goal, DurationNs patience, bool for_order,
                                  std::string* refusal = nullptr);
  /// Whether `steps` alternate vertex, edge, vertex, ... with each edge drivable from the
  /// vertex before it to the vertex after it (what RouteTracker relies on).
  bool drivable(const std::vector<topology::RouteStep>& steps) const;
  /// Makes `next` the current route: swaps the vertex the vehicle holds onto it, cancels
  /// the previous route.
  Status switch_route(RouteTracker next);
  /// Drives to `goal` (re-planning on locks), along `planned` first when given (a route to
  /// `goal` from the vehicle's vertex, just reserved). \return success, or why it failed.
  /// Activity::driving drives for the running order: a withdrawal of the order stops it
  /// (not_permitted) where the vehicle stands once its commanded moves are done.
  Status drive_to(topology::EntityIndex goal, Activity activity, DurationNs patience,
                  std::optional<RouteTracker> planned = std::nullopt);
  FollowResult follow(std::string& failure);
  /// A watch over a command the RAN accepted just now.
  static CommandWatch watch_from_now();
  /// A pending move the RAN lost (CommandWatch) in the latest status, without an end:
  /// why follow fails the order. \pre mutex_ held, status_ set
  std::optional<std::string> lost_move();
  /// Performs an action where the vehicle stands; `for_order`: the running order's operation
  /// (its command is recorded first, OrderBook::action_commanded). \return success or why
  /// it failed.
  Status operate(const ran::ActionCommand& action, Activity activity, bool for_order = false);
  /// Waits for the end of action `command` (named `name` in messages) on the RAN, followed
  /// by `watch`. \return success when it finished, otherwise why not (it failed or was
  /// cancelled, a RAN error, or the RAN lost it: CommandWatch).
  Status await_action(const ran::CommandId& command, const std::string& name, CommandWatch watch);
  /// The running order was restored with its operation at `destination` commanded as
  /// `command` by an earlier life: waits for that command's outcome. \return success when
  /// it finished; why not when it failed, or when the RAN does not report it (it restarted
  /// too, or never got it): whether the operation was done is unknown then, and doing it
  /// again could load or unload twice.
  Status resume_action(const ran::CommandId& command, const Destination& destination);
  void execute_order();
  /// Whether the running order is being withdrawn.
  bool order_withdrawn();
  /// Whether an operator paused the vehicle: it then plans, allocates and begins nothing new
  /// but the hold of the vertex it stands on (an action under way, or one an earlier life
  /// commanded, is completed).
  bool pause_requested();
  /// Whether the action of a restored order, commanded by an earlier life, is still awaited.
  bool adopted_action_pending();
  /// Ends the running order as withdrawn when a withdrawal of it is pending (the vehicle
  /// stands, or is between the order's steps). \return whether it did.
  bool end_pending_withdrawal();
  /// Drives to the nearest vertex of `kind` that can be held; charges there for chargers.
  void go_to_service_vertex(topology::VertexKind kind);
  /// Drives to the nearest vertex of `kind` other than the one the vehicle stands on (or,
  /// with `here_will_do`, stays where it is when that is of `kind`): the nearest one a route
  /// leads to now (one try each).
  /// \return whether it stands on one now (false also when the drive failed on the way).
  bool drive_to_nearest(topology::VertexKind kind, bool here_will_do);

  // ---- making way (make_way.cpp) ----
  /// Asks each of `blockers` (vehicles standing for good in the way to `goal`) to make
  /// way, at most once per kMakeWayRepeat each.
  void ask_make_way(const std::vector<std::string>& blockers, topology::EntityIndex goal);
  /// \return the request to make way still in force, if any (a request older than
  ///         kMakeWayValid is dropped: a requester still blocked asks again).
  std::optional<std::string> make_way_requested();
  /// Drives the standing vehicle off its vertex to a free parking vertex, for whoever
  /// asked. \return whether it moved.
  bool make_way(const std::string& requester);
  /// Gives up the current route after a failure: stops the vehicle, cancels the route's
  /// reservations but for the steps it holds, and, once the vehicle is known to stand,
  /// releases what the footprint does not need (otherwise hold_position does, later). The
  /// route becomes remnant_.
  void abandon_route();
  /// Cancels a route of ours whose steps are unknown (a reply lost, or not to be trusted)
  /// in every partition; failures are logged.
  void cancel_route_quietly(topology::RouteId route);
  /// Cancels `route` where it has reservations (TopologyServices::partitions_touched);
  /// failures are logged.
  void cancel_route_quietly(const RouteTracker& route);
  void release_passed(const ran::VehicleStatus& status);
  void process_notices(bool& replan);
  /// The allocation of `entity` was not granted (yet): raises the wait_alarm warning once
  /// the vehicle has waited that long for it.
  void note_allocation_wait(topology::EntityIndex entity);
  /// An allocation was granted, or the route changed: the wait, if any, is over.
  void end_allocation_wait();
  /// Releases the allocations granted late that nobody claims (LateGrants).
  void give_back_late_grants();
  /// Delays `route` (route_ or remnant_) by `by` from its step `from_step` on: at the owner
  /// of that step's entity, then at the owners of the partitions of the later steps.
  void propagate_delay(RouteTracker& route, std::size_t from_step, DurationNs by);
  /// The first part of propagate_delay: the delay at the owner of the step's entity (which
  /// moves everything of the route it holds from there), followed in `route`.
  /// \return whether that owner took it.
  bool delay_at_owner(RouteTracker& route, std::size_t from_step, DurationNs by);
  /// Waits kRoutePause (real time) before a retry, or until shutdown.
  void pause_before_retry();
  /// Cancels the moves the RAN has not ended and waits (bounded) for a status after the
  /// cancel showing the vehicle still. \return whether it is known to stand with nothing
  /// commanded; false when the cancel did not reach the RAN (the moves stay pending, the
  /// next call cancels them) or no such status came (the next call waits for one again).
  bool stop_vehicle();
  /// Whether the latest status is later than `since` and shows the vehicle still.
  /// \pre mutex_ is held
  bool fresh_and_standing(TimeNs since) const;
  /// The latest status when it is recent and the RAN's statuses are not being refused:
  /// what the RAN says now, not what a RAN said before it went quiet or was replaced.
  /// \pre mutex_ is held
  const ran::VehicleStatus* heard_status() const;
  /// Checks the RAN's errors. \return a failure reason once the order must fail.
  std::optional<std::string> check_errors(const ran::VehicleStatus& status);
  /// Why no status of the RAN is heard: it is silent, or what it reports is refused.
  std::string silence_cause() const;
  void raise_alarm(msg::AlarmSeverity severity, const std::string& text);
  void set_activity(Activity activity);
  void publish_vehicle_state(bool force);
  ran::CommandId next_command_id();

  const std::shared_ptr<const topology::Topology> topology_;
  const SharedClock clock_;
  const LogicalAgentOptions options_;
  std::atomic<bool> stopping_{false};

  // Shared with the callbacks, under mutex_.
  std::mutex mutex_;
  std::condition_variable wake_;
  std::uint64_t events_ = 0;
  OrderBook book_;
  std::deque<msg::ReservationNotice> notices_;
  std::optional<ran::VehicleStatus> status_;
  std::chrono::steady_clock::time_point status_received_{};
  std::map<ran::CommandId, ran::CommandProgress> ended_commands_;  ///< ours, once terminal
  /// The action of the restored running order an earlier life commanded, until its outcome
  /// is known: followed as this life's own commands are (ended_commands_), and not
  /// cancelled as other commands of earlier lives are (earlier_commands_running).
  std::optional<ran::CommandId> adopted_command_;
  std::optional<OrderJournal> journal_;
  /// Orders whose latest change the journal failed to store, to be stored with the next.
  std::map<std::string, Order> unsaved_orders_;
  bool journal_failing_ = false;  ///< the operator was told; until the journal is written again
  /// The orders an earlier life stored, from create() to start() (restore_orders).
  std::vector<Order> restored_;
  /// Paused by an operator (the reason given), until resumed: the vehicle stops on a vertex
  /// and begins nothing new (pause_requested).
  std::optional<std::string> pause_;
  /// The latest request to make way for another vehicle.
  struct MakeWay {
    std::string requester;
    std::string location;
    TimeNs time = 0;
  };
  std::optional<MakeWay> make_way_;

  // Executor state.
  FootprintMonitor monitor_;
  /// Allocations notified as granted that no allocate reply claimed yet.
  LateGrants late_grants_{std::chrono::seconds(2)};
  std::optional<RouteTracker> route_;
  /// The route abandon_route gave up last, until the next route begins: the vehicle may
  /// still hold steps of it (the vertex it stands on), whose windows keep_standing_reserved
  /// keeps ahead of now. Notices about it are not followed: another's delay can only make
  /// its windows longer, so the windows here are at most as long as the timelines' (a
  /// delay asked for from them moves it a little further than needed, never too little).
  std::optional<RouteTracker> remnant_;
  struct PendingMove {
    ran::CommandId id;
    std::size_t target;  ///< the route step the move ends on
    CommandWatch watch;
  };
  std::deque<PendingMove> pending_moves_;  ///< moves the RAN accepted, oldest first, until they end
  std::optional<topology::EntityIndex> vertex_;  ///< where the vehicle stands or last stood
  Activity activity_ = Activity::idle;
  TimeNs idle_since_ = 0;
  std::optional<TimeNs> error_since_;
  /// Partitions that did not say at take_over what an earlier life left there.
  std::vector<std::string> unknown_partitions_;
  /// The routes this life asked for while unknown_partitions_ is not empty (not the
  /// earlier life's: take_over_late leaves them be).
  std::set<topology::RouteId> own_routes_;
  std::chrono::steady_clock::time_point next_late_take_over_{};
  std::multiset<std::pair<topology::RouteId, DurationNs>> own_shift_echoes_;
  std::uint64_t command_counter_ = 0;
  std::uint64_t seen_events_ = 0;
  Activity drive_activity_ = Activity::driving;
  TimeNs charge_retry_at_ = 0;
  /// When a cancel of moves reached the RAN that no standing status has confirmed yet.
  std::optional<TimeNs> stop_asked_;
  bool stop_undelivered_ = false;  ///< a cancel did not reach the RAN (warned once)
  bool position_alarm_raised_ = false;
  bool hold_alarm_raised_ = false;  ///< stranded_on told the operator (until a hold again)
  /// The allocation the vehicle waits for (note_allocation_wait).
  struct AllocationWait {
    topology::EntityIndex entity = topology::kNoEntity;
    TimeNs since = 0;
    bool told = false;  ///< the operator was warned
  };
  std::optional<AllocationWait> allocation_wait_;
  /// Since when commands of an earlier life are seen running (earlier_commands_running).
  std::optional<TimeNs> earlier_commands_since_;
  bool earlier_commands_cancelled_ = false;  ///< their cancel was sent (once)
  TimeNs finish_edge_at_ = 0;       ///< when finish_edge may try next
  bool critical_stop_ = false;      ///< stopped by a critical alarm, not on a vertex since
  /// While finish_edge drives onto it: the vertex its route starts on, which the vehicle has
  /// not reached yet (release_passed must not take it for passed).
  std::optional<topology::EntityIndex> driving_onto_;
  TimeNs clear_way_at_ = 0;         ///< when stranded_on tries to clear the way next
  /// The last drive (or route asked for) stopped because the vehicle was paused, not failed;
  /// cleared by whoever reads it.
  bool stopped_for_pause_ = false;
  bool making_way_ = false;                          ///< driving aside: requests wait
  std::map<std::string, TimeNs> make_way_asked_;     ///< blocker -> when last asked
  std::string command_prefix_;
  std::mt19937_64 route_ids_;
  msg::VehicleState last_published_;
  std::chrono::steady_clock::time_point last_publication_{};

  // DDS entities: the participant first (destroyed last), callbacks' sources last.
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<TopologyServices> services_;
  std::unique_ptr<dds::Writer<msg::OrderProgress>> progress_writer_;
  std::unique_ptr<dds::Writer<msg::VehicleState>> vehicle_writer_;
  std::unique_ptr<dds::Writer<msg::OperatorAlarm>> alarm_writer_;
  std::unique_ptr<dds::Writer<msg::MakeWayRequest>> make_way_writer_;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat_;
  std::unique_ptr<ran::RanClient> ran_;
  std::unique_ptr<dds::Reader<msg::ReservationNotice>> notice_reader_;
  std::unique_ptr<dds::Reader<msg::MakeWayRequest>> make_way_reader_;
  std::unique_ptr<dds::ServiceServer<msg::OrderRequest, msg::OrderReply>> order_server_;
  std::unique_ptr<dds::ServiceServer<msg::OrderWithdrawRequest, msg::OrderWithdrawReply>> withdraw_server_;
  std::unique_ptr<dds::ServiceServer<msg::VehiclePauseRequest, msg::StatusReply>> pause_server_;
  std::thread executor_;
};

}  // namespace drover::logical_agent

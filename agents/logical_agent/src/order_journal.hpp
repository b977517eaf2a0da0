#pragma once
// The logical agent's order journal: an SQLite file with every order the agent knows (its
// queue, the running order with how far it got, the ended orders it remembers), so that a
// restarted agent (a crash, kill -9, a reboot) carries on with its orders instead of
// losing them (docs/logical-agent.md, "Persistence").
//
// The agent stores an order before it acknowledges it and on every change after; on start
// it loads them all and rebuilds its OrderBook (OrderBook::restore).

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "agents/logical_agent/src/order_book.hpp"
#include "drover/common/result.hpp"

namespace drover::logical_agent {

/// An order journal file, open for one process. Not thread-safe: one thread at a time.
/// Durable (a change stored survives kill -9 and a power cut) and exclusive (a second agent
/// on the same file is refused) as sqlite::Database.
class OrderJournal {
 public:
  /// The schema version this build writes and reads.
  static constexpr int kSchemaVersion = 1;

  /// Opens the journal of vehicle `vehicle` in `file`, creating it if it does not exist or
  /// is empty. \param ended_kept  ended orders kept, the oldest forgotten first (as the
  /// agent's OrderBook).
  /// \return the journal, or an error naming the file: io (cannot be opened or created),
  ///         parse (not an SQLite database, damaged, not an order journal, another schema
  ///         version), conflict (another vehicle's), unavailable (another process has it).
  static Result<OrderJournal> open(const std::filesystem::path& file, std::string_view vehicle,
                                   std::size_t ended_kept = OrderBook::kEndedKept);

  OrderJournal(OrderJournal&&) noexcept;
  OrderJournal& operator=(OrderJournal&&) noexcept;
  ~OrderJournal();

  const std::filesystem::path& file() const noexcept;

  /// Stores `order` as the newest order, durable when it returns. A stored order of the
  /// same name (one the agent has forgotten) is replaced.
  /// \return io (disk full, I/O error) or parse (a damaged file), naming the file; then
  ///         nothing of it is stored.
  Status add(const Order& order);
  /// Stores the new state of `order` (stored before by add; stored as the newest if not),
  /// durable when it returns. Once it has ended, the oldest ended orders beyond ended_kept
  /// are forgotten. \return errors as add.
  Status update(const Order& order);

  /// Every stored order, oldest first. Destinations carry their vertex ids only
  /// (`location` is topology::kNoEntity): the caller resolves them against its topology.
  /// \return parse naming the file, table, row and column for a value of the wrong type,
  ///         an unknown state, destinations that are not the JSON this journal writes, a
  ///         destination index out of range, or a second running order.
  Result<std::vector<Order>> load();

  /// Stores that an operator paused the vehicle for `reason` (a pause that must outlive the
  /// agent), or, with nullopt, that it was resumed; durable when it returns.
  /// \return io or parse naming the file; then the stored pause is unchanged.
  Status store_pause(const std::optional<std::string>& reason);
  /// The stored pause's reason, nullopt when the vehicle is not paused.
  /// \return parse naming the file for a reason that is not text.
  Result<std::optional<std::string>> load_pause();

 private:
  struct Connection;
  explicit OrderJournal(std::unique_ptr<Connection> connection);
  std::unique_ptr<Connection> connection_;
};

}  // namespace drover::logical_agent

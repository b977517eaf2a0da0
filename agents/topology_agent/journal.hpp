#pragma once
// The topology agent's journal: an SQLite database with the committed state of every entity
// the agent ever changed (reservations real and shadow, locks, allocations, versions) and
// its id counters, so that a restarted agent loses nothing committed
// (docs/topology-agent.md, "Persistence").
//
// After each operation the agent saves the snapshot of the entities it changed
// (TimelineSet::snapshot(changed_entities(...))) before it replies or publishes; on start it
// rebuilds its TimelineSet with restore_timelines. Prepared holds and waiting allocation
// requests are never stored (presumed abort).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"

namespace drover::topology_agent {

/// A journal file, open for one process. Not thread-safe: one thread at a time.
///
/// Durability: WAL mode with synchronous=FULL, one transaction per save: once save has
/// returned, the operation survives kill -9 (and a power cut); a crash during save leaves the
/// journal as it was before that save, never half of it.
/// Exclusive: the file stays locked while open (locking_mode=EXCLUSIVE), so a second agent
/// started on the same file is refused instead of interleaving its writes.
class Journal {
 public:
  /// The schema version this build writes and reads.
  static constexpr int kSchemaVersion = 1;

  /// Opens the journal in `file`, creating it (and its schema) if it does not exist or is
  /// empty. \param topology_key what the journal belongs to (see journal_key): recorded at
  /// creation, and an existing journal must carry the same.
  /// \return the journal, or an error whose message names the file:
  ///   io            the file cannot be opened or created (missing directory, permissions)
  ///   parse         not an SQLite database, a damaged one, not a Drover journal, or a
  ///                 schema version other than kSchemaVersion
  ///   conflict      a journal of another topology or partition
  ///   unavailable   another process has it open
  static Result<Journal> open(const std::filesystem::path& file, std::string_view topology_key);

  Journal(Journal&&) noexcept;
  Journal& operator=(Journal&&) noexcept;
  ~Journal();

  const std::filesystem::path& file() const noexcept;

  /// Replaces the stored state of the entities in `changed` with theirs and stores its id
  /// counters, in one transaction, durable when it returns. Entities not in `changed` keep
  /// their stored state. \return an error naming the file and SQLite's message: io (disk
  /// full, I/O error), parse (a damaged file), invalid_argument (an item filed under another
  /// entity, a prepared one, the same item twice). Then nothing of this save is stored, and
  /// the caller's memory is ahead of its journal: it must not acknowledge the operation
  /// (the topology agent stops, and its restart comes back to the journal's state).
  Status save(const topology::TimelineSnapshot& changed);

  /// Everything stored: the entities ascending, each with its reservations and locks in
  /// timeline order (route ids compared as stored, signed 64-bit), and the id counters.
  /// A new journal gives an empty snapshot with both counters at 1.
  /// \return parse naming the file, table and row for a value of the wrong type or range.
  Result<topology::TimelineSnapshot> load();

 private:
  struct Connection;
  explicit Journal(std::unique_ptr<Connection> connection);
  std::unique_ptr<Connection> connection_;
};

/// Names what a journal belongs to: the topology's name, the partition (empty: the whole
/// topology) and a fingerprint of its entity ids in index order and of its conflict sets,
/// since a journal's entity indices and shadows mean nothing for another topology.
std::string journal_key(const topology::Topology& topology, std::string_view partition);

/// Every entity's version, to find later which ones an operation changed.
std::vector<std::uint64_t> versions(const topology::TimelineSet& set);
/// The owned entities whose version differs from `before` (from versions() before the
/// operation): what the operation changed, and so what to save.
std::vector<topology::EntityIndex> changed_entities(const topology::TimelineSet& set,
                                                    const std::vector<std::uint64_t>& before);

/// The restore path: loads the journal and rebuilds the timelines from it
/// (TimelineSet::restore). \return the load's errors, or restore's invalid_argument with
/// the journal's file name in front (a journal that breaks the invariants).
Result<topology::TimelineSet> restore_timelines(Journal& journal,
                                                std::vector<std::vector<topology::EntityIndex>> conflict_sets,
                                                std::vector<bool> owned);

}  // namespace drover::topology_agent

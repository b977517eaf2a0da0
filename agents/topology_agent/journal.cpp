// The topology agent's SQLite journal; see journal.hpp. The schema:
//   schema_version(version)                       one row: kSchemaVersion
//   meta(key, value)                              topology_key, next_lock_id, next_prepare_id
//   entities(entity, version, holder, held_route, held_step)
//   reservations(entity, agent, route, step, origin, start_ns, end_ns)   committed only
//   locks(id, entity, start_ns, end_ns, operator, reason)
// Unsigned 64-bit ids and versions are stored as SQLite's signed INTEGER, bit for bit.

#include "agents/topology_agent/journal.hpp"

#include <cinttypes>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "agents/sqlite/database.hpp"

namespace drover::topology_agent {

using sqlite::Statement;
using sqlite::Value;
using sqlite::stored;
using topology::EntityIndex;
using topology::EntitySnapshot;
using topology::TimelineSnapshot;

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL) STRICT;
CREATE TABLE meta (key TEXT PRIMARY KEY, value ANY NOT NULL) STRICT;
CREATE TABLE entities (
  entity INTEGER PRIMARY KEY,
  version INTEGER NOT NULL,
  holder TEXT,
  held_route INTEGER,
  held_step INTEGER,
  CHECK ((holder IS NULL) = (held_route IS NULL) AND (holder IS NULL) = (held_step IS NULL))
) STRICT;
CREATE TABLE reservations (
  entity INTEGER NOT NULL,
  agent TEXT NOT NULL,
  route INTEGER NOT NULL,
  step INTEGER NOT NULL,
  origin INTEGER NOT NULL,
  start_ns INTEGER NOT NULL,
  end_ns INTEGER NOT NULL,
  PRIMARY KEY (entity, agent, route, step)
) STRICT, WITHOUT ROWID;
CREATE TABLE locks (
  id INTEGER PRIMARY KEY,
  entity INTEGER NOT NULL,
  start_ns INTEGER NOT NULL,
  end_ns INTEGER NOT NULL,
  operator TEXT NOT NULL,
  reason TEXT NOT NULL
) STRICT;
CREATE INDEX locks_by_entity ON locks (entity);
)sql";

constexpr sqlite::Schema kJournalSchema{
    "journal", kSchema, Journal::kSchemaVersion, "topology_key",
    "INSERT INTO meta VALUES ('next_lock_id', 1), ('next_prepare_id', 1);"};

EntityIndex entity_at(sqlite::RowReader& row, int column) { return row.small(column, topology::kNoEntity - 1); }

}  // namespace

struct Journal::Connection {
  sqlite::Database db;
  // Declared after db: finalized before it closes.
  Statement delete_reservations, delete_locks, upsert_entity, insert_reservation, insert_lock, set_meta;

  explicit Connection(sqlite::Database database) : db(std::move(database)) {}

  Status prepare_statements() {
    const std::pair<Statement*, const char*> statements[] = {
        {&delete_reservations, "DELETE FROM reservations WHERE entity = ?"},
        {&delete_locks, "DELETE FROM locks WHERE entity = ?"},
        {&upsert_entity, "INSERT OR REPLACE INTO entities VALUES (?, ?, ?, ?, ?)"},
        {&insert_reservation, "INSERT INTO reservations VALUES (?, ?, ?, ?, ?, ?, ?)"},
        {&insert_lock, "INSERT INTO locks VALUES (?, ?, ?, ?, ?, ?)"},
        {&set_meta, "UPDATE meta SET value = ? WHERE key = ?"},
    };
    for (const auto& [statement, sql] : statements) {
      auto prepared = db.prepare(sql, "prepare the statements");
      if (!prepared) return unexpected(std::move(prepared).error());
      *statement = std::move(*prepared);
    }
    return {};
  }

  /// The statements of one save, inside its transaction.
  Status write(const TimelineSnapshot& changed) {
    for (const EntitySnapshot& es : changed.entities) {
      const std::string what = "save entity " + std::to_string(es.entity);
      const std::int64_t entity = es.entity;
      if (Status ok = db.run(delete_reservations, {entity}, what); !ok) return ok;
      if (Status ok = db.run(delete_locks, {entity}, what); !ok) return ok;
      Value holder = nullptr, route = nullptr, step = nullptr;
      if (es.holding) {
        holder = std::string_view(es.holding->agent);
        route = stored(es.holding->step.route);
        step = std::int64_t{es.holding->step.step};
      }
      if (Status ok = db.run(upsert_entity, {entity, stored(es.version), holder, route, step}, what); !ok) {
        return ok;
      }
      for (const topology::Reservation& r : es.reservations) {
        if (Status ok = db.run(insert_reservation,
                            {entity, std::string_view(r.agent), stored(r.route), std::int64_t{r.step},
                             std::int64_t{r.origin}, r.window.start, r.window.end},
                            what);
            !ok) {
          return ok;
        }
      }
      for (const topology::Lock& lock : es.locks) {
        if (Status ok = db.run(insert_lock,
                            {stored(lock.id), entity, lock.window.start, lock.window.end,
                             std::string_view(lock.operator_id), std::string_view(lock.reason)},
                            what);
            !ok) {
          return ok;
        }
      }
    }
    if (Status ok = db.run(set_meta, {stored(changed.next_lock_id), std::string_view("next_lock_id")},
                        "save the lock id counter");
        !ok) {
      return ok;
    }
    return db.run(set_meta, {stored(changed.next_prepare_id), std::string_view("next_prepare_id")},
               "save the prepare id counter");
  }
};

Journal::Journal(std::unique_ptr<Connection> connection) : connection_(std::move(connection)) {}
Journal::Journal(Journal&&) noexcept = default;
Journal& Journal::operator=(Journal&&) noexcept = default;
Journal::~Journal() = default;

const std::filesystem::path& Journal::file() const noexcept { return connection_->db.file(); }

Result<Journal> Journal::open(const std::filesystem::path& file, std::string_view topology_key) {
  auto db = sqlite::Database::open(file, kJournalSchema, topology_key);
  if (!db) return unexpected(std::move(db).error());
  auto c = std::make_unique<Connection>(std::move(*db));
  if (Status ok = c->prepare_statements(); !ok) return unexpected(std::move(ok).error());
  return Journal(std::move(c));
}

Status Journal::save(const TimelineSnapshot& changed) {
  Connection& c = *connection_;
  // What the schema cannot express: items filed under another entity, uncommitted items.
  for (const EntitySnapshot& es : changed.entities) {
    for (const topology::Reservation& r : es.reservations) {
      if (r.entity != es.entity || r.prepared) {
        return fail(ErrorCode::invalid_argument,
                    c.db.where() + ": save: entity " + std::to_string(es.entity) +
                        " carries a reservation " + (r.prepared ? "that is prepared" : "of entity " + std::to_string(r.entity)));
      }
    }
    for (const topology::Lock& lock : es.locks) {
      if (lock.entity != es.entity) {
        return fail(ErrorCode::invalid_argument, c.db.where() + ": save: entity " +
                                                     std::to_string(es.entity) + " carries lock " +
                                                     std::to_string(lock.id) + " of entity " +
                                                     std::to_string(lock.entity));
      }
    }
  }
  return c.db.transaction("a save", [&] { return c.write(changed); });
}

Result<TimelineSnapshot> Journal::load() {
  Connection& c = *connection_;
  TimelineSnapshot snapshot;
  std::map<EntityIndex, std::size_t> position;  // entity -> index in snapshot.entities
  const auto entity_of = [&](sqlite::RowReader& row, EntityIndex entity) -> EntitySnapshot* {
    const auto found = position.find(entity);
    if (found == position.end()) {
      row.complain("entity " + std::to_string(entity) + " has no row in table entities");
      return nullptr;
    }
    return &snapshot.entities[found->second];
  };
  std::optional<std::uint64_t> next_lock_id, next_prepare_id;
  Status loaded = c.db.read_transaction("loading", [&]() -> Status {
    Status read = c.db.each_row(
        "SELECT entity, version, holder, held_route, held_step FROM entities ORDER BY entity",
        "entities", [&](sqlite::RowReader& row) {
          EntitySnapshot es;
          es.entity = entity_at(row, 0);
          es.version = row.unsigned_integer(1);
          if (!row.null(2)) {
            es.holding = topology::Holding{row.text(2), {row.unsigned_integer(3),
                                                         row.small(4, std::numeric_limits<std::uint32_t>::max())}};
          }
          position.emplace(es.entity, snapshot.entities.size());
          snapshot.entities.push_back(std::move(es));
        });
    if (!read) return read;
    read = c.db.each_row(
        "SELECT entity, agent, route, step, origin, start_ns, end_ns FROM reservations "
        "ORDER BY entity, start_ns, end_ns, agent, route, step, origin",
        "reservations", [&](sqlite::RowReader& row) {
          topology::Reservation r;
          r.entity = entity_at(row, 0);
          r.agent = row.text(1);
          r.route = row.unsigned_integer(2);
          r.step = row.small(3, std::numeric_limits<std::uint32_t>::max());
          r.origin = entity_at(row, 4);
          r.window = {row.integer(5), row.integer(6)};
          if (EntitySnapshot* es = entity_of(row, r.entity)) es->reservations.push_back(std::move(r));
        });
    if (!read) return read;
    read = c.db.each_row(
        "SELECT id, entity, start_ns, end_ns, operator, reason FROM locks "
        "ORDER BY entity, start_ns, id",
        "locks", [&](sqlite::RowReader& row) {
          topology::Lock lock;
          lock.id = row.unsigned_integer(0);
          lock.entity = entity_at(row, 1);
          lock.window = {row.integer(2), row.integer(3)};
          lock.operator_id = row.text(4);
          lock.reason = row.text(5);
          if (EntitySnapshot* es = entity_of(row, lock.entity)) es->locks.push_back(std::move(lock));
        });
    if (!read) return read;
    return c.db.each_row("SELECT key, value FROM meta", "meta", [&](sqlite::RowReader& row) {
      const std::string key = row.text(0);
      if (key == "next_lock_id") next_lock_id = row.unsigned_integer(1);
      if (key == "next_prepare_id") next_prepare_id = row.unsigned_integer(1);
    });
  });
  if (loaded && (!next_lock_id || !next_prepare_id)) {
    loaded = unexpected(c.db.content_error("table meta lacks next_lock_id or next_prepare_id"));
  }
  if (!loaded) return unexpected(std::move(loaded).error());
  snapshot.next_lock_id = *next_lock_id;
  snapshot.next_prepare_id = *next_prepare_id;
  return snapshot;
}

std::string journal_key(const topology::Topology& topology, std::string_view partition) {
  // FNV-1a: stable across builds and platforms, unlike std::hash.
  std::uint64_t hash = 14695981039346656037ull;
  const auto mix = [&hash](std::string_view bytes) {
    for (const unsigned char byte : bytes) {
      hash ^= byte;
      hash *= 1099511628211ull;
    }
  };
  mix(std::to_string(topology.entity_count()));
  for (EntityIndex e = 0; e < topology.entity_count(); ++e) {
    mix("\n");
    mix(topology.id(e));
    for (EntityIndex f : topology.conflicts(e)) mix("," + std::to_string(f));
  }
  char fingerprint[17];
  std::snprintf(fingerprint, sizeof fingerprint, "%016" PRIx64, hash);
  return "topology '" + topology.name() + "' " +
         (partition.empty() ? std::string("(all partitions)")
                            : "partition '" + std::string(partition) + "'") +
         " fingerprint " + fingerprint;
}

std::vector<std::uint64_t> versions(const topology::TimelineSet& set) {
  std::vector<std::uint64_t> result(set.entity_count());
  for (EntityIndex e = 0; e < result.size(); ++e) result[e] = set.version(e);
  return result;
}

std::vector<EntityIndex> changed_entities(const topology::TimelineSet& set,
                                          const std::vector<std::uint64_t>& before) {
  std::vector<EntityIndex> changed;
  for (EntityIndex e = 0; e < set.entity_count(); ++e) {
    const std::uint64_t was = e < before.size() ? before[e] : 0;
    if (set.owns(e) && set.version(e) != was) changed.push_back(e);
  }
  return changed;
}

Result<topology::TimelineSet> restore_timelines(
    Journal& journal, std::vector<std::vector<EntityIndex>> conflict_sets, std::vector<bool> owned) {
  auto snapshot = journal.load();
  if (!snapshot) return unexpected(std::move(snapshot).error());
  auto set = topology::TimelineSet::restore(std::move(conflict_sets), std::move(owned), *snapshot);
  if (!set) {
    return fail(set.error().code, "journal " + journal.file().string() + ": " + set.error().message);
  }
  return std::move(set).value();
}

}  // namespace drover::topology_agent

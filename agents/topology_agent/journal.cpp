// The topology agent's SQLite journal; see journal.hpp. The schema:
//   schema_version(version)                       one row: kSchemaVersion
//   meta(key, value)                              topology_key, next_lock_id, next_prepare_id
//   entities(entity, version, holder, held_route, held_step)
//   reservations(entity, agent, route, step, origin, start_ns, end_ns)   committed only
//   locks(id, entity, start_ns, end_ns, operator, reason)
// Unsigned 64-bit ids and versions are stored as SQLite's signed INTEGER, bit for bit.

#include "agents/topology_agent/journal.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <variant>

namespace drover::topology_agent {

namespace fs = std::filesystem;
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

/// Owns a prepared statement.
class Statement {
 public:
  Statement() = default;
  explicit Statement(sqlite3_stmt* statement) : statement_(statement) {}
  Statement(Statement&& other) noexcept : statement_(std::exchange(other.statement_, nullptr)) {}
  Statement& operator=(Statement&& other) noexcept {
    std::swap(statement_, other.statement_);
    return *this;
  }
  ~Statement() { sqlite3_finalize(statement_); }
  sqlite3_stmt* get() const noexcept { return statement_; }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

/// A value bound to a statement parameter.
using Value = std::variant<std::nullptr_t, std::int64_t, std::string_view>;

std::int64_t stored(std::uint64_t value) { return static_cast<std::int64_t>(value); }

ErrorCode code_of(int sqlite_code) {
  switch (sqlite_code & 0xff) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return ErrorCode::unavailable;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return ErrorCode::parse;
    case SQLITE_CONSTRAINT: return ErrorCode::invalid_argument;
    default: return ErrorCode::io;
  }
}

}  // namespace

struct Journal::Connection {
  std::filesystem::path file;
  sqlite3* db = nullptr;
  Statement delete_reservations, delete_locks, upsert_entity, insert_reservation, insert_lock,
      set_meta;

  // Statements are members, finalized after this body; close_v2 waits for them.
  ~Connection() { sqlite3_close_v2(db); }

  std::string where() const { return "journal " + file.string(); }

  /// The error SQLite reported for `what`.
  Error error(int sqlite_code, const std::string& what) const {
    if ((sqlite_code & 0xff) == SQLITE_BUSY) {
      return Error{ErrorCode::unavailable,
                   where() + " is in use by another process (" + what + ": " + sqlite3_errmsg(db) + ")"};
    }
    return Error{code_of(sqlite_code), where() + ": " + what + ": " + sqlite3_errmsg(db)};
  }
  Error content_error(const std::string& message) const {
    return Error{ErrorCode::parse, where() + ": " + message};
  }

  Status exec(const char* sql, const std::string& what) {
    const int rc = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) return unexpected(error(rc, what));
    return {};
  }

  Result<Statement> prepare(const char* sql, const std::string& what) {
    sqlite3_stmt* statement = nullptr;
    const int rc = sqlite3_prepare_v3(db, sql, -1, SQLITE_PREPARE_PERSISTENT, &statement, nullptr);
    if (rc != SQLITE_OK) return unexpected(error(rc, what));
    return Statement(statement);
  }

  /// Binds `values` to the statement's parameters in order and runs it to completion.
  Status run(const Statement& statement, std::initializer_list<Value> values,
             const std::string& what) {
    sqlite3_stmt* s = statement.get();
    int rc = SQLITE_OK;
    int index = 1;
    for (const Value& value : values) {
      if (rc != SQLITE_OK) break;
      if (const auto* number = std::get_if<std::int64_t>(&value)) {
        rc = sqlite3_bind_int64(s, index, *number);
      } else if (const auto* text = std::get_if<std::string_view>(&value)) {
        rc = sqlite3_bind_text(s, index, text->data(), static_cast<int>(text->size()),
                               SQLITE_TRANSIENT);
      } else {
        rc = sqlite3_bind_null(s, index);
      }
      ++index;
    }
    if (rc == SQLITE_OK) rc = sqlite3_step(s);
    std::optional<Error> failed;
    if (rc != SQLITE_DONE) failed = error(rc, what);  // before reset, which may change errmsg
    sqlite3_reset(s);
    sqlite3_clear_bindings(s);
    if (failed) return unexpected(std::move(*failed));
    return {};
  }

  /// The first column of the first row of `sql`, if it has a row.
  Result<std::optional<std::string>> first_text(const char* sql, const std::string& what) {
    auto statement = prepare(sql, what);
    if (!statement) return unexpected(std::move(statement).error());
    const int rc = sqlite3_step(statement->get());
    if (rc == SQLITE_DONE) return std::optional<std::string>();
    if (rc != SQLITE_ROW) return unexpected(error(rc, what));
    const auto* text = sqlite3_column_text(statement->get(), 0);
    return std::optional<std::string>(text ? reinterpret_cast<const char*>(text) : "");
  }
  Result<std::optional<std::int64_t>> first_integer(const char* sql, const std::string& what) {
    auto statement = prepare(sql, what);
    if (!statement) return unexpected(std::move(statement).error());
    const int rc = sqlite3_step(statement->get());
    if (rc == SQLITE_DONE) return std::optional<std::int64_t>();
    if (rc != SQLITE_ROW) return unexpected(error(rc, what));
    if (sqlite3_column_type(statement->get(), 0) != SQLITE_INTEGER) {
      return unexpected(content_error(what + ": not an integer"));
    }
    return std::optional<std::int64_t>(sqlite3_column_int64(statement->get(), 0));
  }

  /// Creates the schema in an empty database, or checks an existing one.
  Status initialize_or_check(std::string_view topology_key) {
    const auto tables = first_integer("SELECT count(*) FROM sqlite_schema", "read the schema");
    if (!tables) return unexpected(tables.error());
    if (**tables == 0) {
      if (Status created = exec(kSchema, "create the schema"); !created) return created;
      const std::string fill =
          "INSERT INTO schema_version VALUES (" + std::to_string(kSchemaVersion) + ");"
          "INSERT INTO meta VALUES ('next_lock_id', 1), ('next_prepare_id', 1);";
      if (Status filled = exec(fill.c_str(), "fill the schema"); !filled) return filled;
      auto insert_key = prepare("INSERT INTO meta VALUES ('topology_key', ?)", "record the topology");
      if (!insert_key) return unexpected(insert_key.error());
      return run(*insert_key, {topology_key}, "record the topology");
    }
    const auto has_version = first_integer(
        "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name = 'schema_version'",
        "read the schema");
    if (!has_version) return unexpected(has_version.error());
    if (**has_version == 0) {
      return unexpected(content_error("an SQLite database but not a Drover journal (no schema_version table)"));
    }
    const auto version = first_integer("SELECT version FROM schema_version", "read the schema version");
    if (!version) return unexpected(version.error());
    if (!*version || **version != kSchemaVersion) {
      return unexpected(content_error(
          "schema version " + (*version ? std::to_string(**version) : std::string("missing")) +
          ", this build reads version " + std::to_string(kSchemaVersion)));
    }
    const auto key = first_text("SELECT value FROM meta WHERE key = 'topology_key'", "read the topology key");
    if (!key) return unexpected(key.error());
    if (!*key) return unexpected(content_error("no topology key in table meta"));
    if (**key != topology_key) {
      return fail(ErrorCode::conflict, where() + " belongs to " + **key + ", not to " +
                                           std::string(topology_key) +
                                           " (move it away to start this one afresh)");
    }
    return {};
  }

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
      auto prepared = prepare(sql, "prepare the statements");
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
      if (Status ok = run(delete_reservations, {entity}, what); !ok) return ok;
      if (Status ok = run(delete_locks, {entity}, what); !ok) return ok;
      Value holder = nullptr, route = nullptr, step = nullptr;
      if (es.holding) {
        holder = std::string_view(es.holding->agent);
        route = stored(es.holding->step.route);
        step = std::int64_t{es.holding->step.step};
      }
      if (Status ok = run(upsert_entity, {entity, stored(es.version), holder, route, step}, what); !ok) {
        return ok;
      }
      for (const topology::Reservation& r : es.reservations) {
        if (Status ok = run(insert_reservation,
                            {entity, std::string_view(r.agent), stored(r.route), std::int64_t{r.step},
                             std::int64_t{r.origin}, r.window.start, r.window.end},
                            what);
            !ok) {
          return ok;
        }
      }
      for (const topology::Lock& lock : es.locks) {
        if (Status ok = run(insert_lock,
                            {stored(lock.id), entity, lock.window.start, lock.window.end,
                             std::string_view(lock.operator_id), std::string_view(lock.reason)},
                            what);
            !ok) {
          return ok;
        }
      }
    }
    if (Status ok = run(set_meta, {stored(changed.next_lock_id), std::string_view("next_lock_id")},
                        "save the lock id counter");
        !ok) {
      return ok;
    }
    return run(set_meta, {stored(changed.next_prepare_id), std::string_view("next_prepare_id")},
               "save the prepare id counter");
  }
};

namespace {

/// Reads the columns of one row of a table, checking types and ranges; the first problem is
/// kept as the error.
class RowReader {
 public:
  /// \param where  names the journal in messages
  RowReader(std::string where, sqlite3_stmt* statement, const char* table)
      : where_(std::move(where)), statement_(statement), table_(table) {}

  void next_row() { ++row_; }
  const std::optional<Error>& error() const { return error_; }

  std::int64_t integer(int column) {
    if (sqlite3_column_type(statement_, column) != SQLITE_INTEGER) {
      complain(column, "is not an integer");
      return 0;
    }
    return sqlite3_column_int64(statement_, column);
  }
  std::uint64_t unsigned_integer(int column) { return static_cast<std::uint64_t>(integer(column)); }
  /// An integer in [0, limit].
  std::uint32_t small(int column, std::uint32_t limit) {
    const std::int64_t value = integer(column);
    if (value < 0 || value > std::int64_t{limit}) {
      complain(column, "is out of range (" + std::to_string(value) + ")");
      return 0;
    }
    return static_cast<std::uint32_t>(value);
  }
  EntityIndex entity(int column) { return small(column, topology::kNoEntity - 1); }
  std::string text(int column) {
    if (sqlite3_column_type(statement_, column) != SQLITE_TEXT) {
      complain(column, "is not text");
      return {};
    }
    return reinterpret_cast<const char*>(sqlite3_column_text(statement_, column));
  }
  bool null(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }

  void complain(int column, const std::string& problem) {
    complain(std::string("column ") + sqlite3_column_name(statement_, column) + " " + problem);
  }
  void complain(const std::string& problem) {
    if (!error_) {
      error_ = Error{ErrorCode::parse, where_ + ": table " + std::string(table_) + " row " +
                                           std::to_string(row_) + ": " + problem};
    }
  }

 private:
  std::string where_;
  sqlite3_stmt* statement_;
  const char* table_;
  std::size_t row_ = 0;
  std::optional<Error> error_;
};

}  // namespace

Journal::Journal(std::unique_ptr<Connection> connection) : connection_(std::move(connection)) {}
Journal::Journal(Journal&&) noexcept = default;
Journal& Journal::operator=(Journal&&) noexcept = default;
Journal::~Journal() = default;

const std::filesystem::path& Journal::file() const noexcept { return connection_->file; }

Result<Journal> Journal::open(const std::filesystem::path& file, std::string_view topology_key) {
  auto c = std::make_unique<Connection>();
  c->file = file;
  const int rc = sqlite3_open_v2(file.c_str(), &c->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                                 nullptr);
  if (rc != SQLITE_OK) {
    std::error_code ignored;
    const std::string hint =
        fs::is_directory(file, ignored)                    ? " (it is a directory)"
        : !fs::is_directory(file.parent_path().empty() ? "." : file.parent_path(), ignored)
            ? " (its directory does not exist)"
            : "";
    return fail(ErrorCode::io, c->where() + ": cannot open or create it: " +
                                   (c->db ? sqlite3_errmsg(c->db) : sqlite3_errstr(rc)) + hint);
  }
  sqlite3_extended_result_codes(c->db, 1);
  if (sqlite3_db_readonly(c->db, "main") == 1) {  // SQLite falls back to reading silently
    return fail(ErrorCode::io, c->where() + ": cannot open it for writing (read-only file)");
  }
  // Exclusive first: entering WAL mode under it keeps the WAL index in process memory and
  // the file locked for as long as the journal is open.
  if (Status ok = c->exec("PRAGMA locking_mode = EXCLUSIVE", "set the locking mode"); !ok) {
    return unexpected(std::move(ok).error());
  }
  const auto mode = c->first_text("PRAGMA journal_mode = WAL", "switch to WAL mode");
  if (!mode) return unexpected(mode.error());
  if (*mode != "wal") {
    return fail(ErrorCode::io, c->where() + ": cannot switch to WAL mode (journal mode " +
                                   mode->value_or("unknown") + ")");
  }
  if (Status ok = c->exec("PRAGMA synchronous = FULL", "set synchronous mode"); !ok) {
    return unexpected(std::move(ok).error());
  }
  const auto check = c->first_text("PRAGMA quick_check", "check the database");
  if (!check) return unexpected(check.error());
  if (*check != "ok") {
    std::string report = check->value_or("no answer from quick_check");
    std::replace(report.begin(), report.end(), '\n', ' ');
    return unexpected(c->content_error("damaged: " + report));
  }
  if (Status ok = c->exec("BEGIN IMMEDIATE", "start"); !ok) return unexpected(std::move(ok).error());
  Status ready = c->initialize_or_check(topology_key);
  if (ready) ready = c->exec("COMMIT", "commit the schema");
  if (!ready) {
    sqlite3_exec(c->db, "ROLLBACK", nullptr, nullptr, nullptr);
    return unexpected(std::move(ready).error());
  }
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
                    c.where() + ": save: entity " + std::to_string(es.entity) +
                        " carries a reservation " + (r.prepared ? "that is prepared" : "of entity " + std::to_string(r.entity)));
      }
    }
    for (const topology::Lock& lock : es.locks) {
      if (lock.entity != es.entity) {
        return fail(ErrorCode::invalid_argument, c.where() + ": save: entity " +
                                                     std::to_string(es.entity) + " carries lock " +
                                                     std::to_string(lock.id) + " of entity " +
                                                     std::to_string(lock.entity));
      }
    }
  }
  if (Status ok = c.exec("BEGIN IMMEDIATE", "start a save"); !ok) return ok;
  Status saved = c.write(changed);
  if (saved) saved = c.exec("COMMIT", "commit a save");
  if (!saved) sqlite3_exec(c.db, "ROLLBACK", nullptr, nullptr, nullptr);
  return saved;
}

Result<TimelineSnapshot> Journal::load() {
  Connection& c = *connection_;
  if (Status ok = c.exec("BEGIN", "start loading"); !ok) return unexpected(std::move(ok).error());
  TimelineSnapshot snapshot;
  std::map<EntityIndex, std::size_t> position;  // entity -> index in snapshot.entities

  // Runs `sql`, handing each row to `read`; stops at the first reader or SQLite error.
  const auto each_row = [&](const char* sql, const char* table, const auto& read) -> Status {
    auto statement = c.prepare(sql, std::string("read table ") + table);
    if (!statement) return unexpected(std::move(statement).error());
    RowReader row(c.where(), statement->get(), table);
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(statement->get())) == SQLITE_ROW) {
      row.next_row();
      read(row);
      if (row.error()) return unexpected(*row.error());
    }
    if (rc != SQLITE_DONE) return unexpected(c.error(rc, std::string("read table ") + table));
    return {};
  };
  const auto entity_of = [&](RowReader& row, EntityIndex entity) -> EntitySnapshot* {
    const auto found = position.find(entity);
    if (found == position.end()) {
      row.complain("entity " + std::to_string(entity) + " has no row in table entities");
      return nullptr;
    }
    return &snapshot.entities[found->second];
  };

  Status loaded = each_row(
      "SELECT entity, version, holder, held_route, held_step FROM entities ORDER BY entity",
      "entities", [&](RowReader& row) {
        EntitySnapshot es;
        es.entity = row.entity(0);
        es.version = row.unsigned_integer(1);
        if (!row.null(2)) {
          es.holding = topology::Holding{row.text(2), {row.unsigned_integer(3),
                                                       row.small(4, std::numeric_limits<std::uint32_t>::max())}};
        }
        position.emplace(es.entity, snapshot.entities.size());
        snapshot.entities.push_back(std::move(es));
      });
  if (loaded) {
    loaded = each_row(
        "SELECT entity, agent, route, step, origin, start_ns, end_ns FROM reservations "
        "ORDER BY entity, start_ns, end_ns, agent, route, step, origin",
        "reservations", [&](RowReader& row) {
          topology::Reservation r;
          r.entity = row.entity(0);
          r.agent = row.text(1);
          r.route = row.unsigned_integer(2);
          r.step = row.small(3, std::numeric_limits<std::uint32_t>::max());
          r.origin = row.entity(4);
          r.window = {row.integer(5), row.integer(6)};
          if (EntitySnapshot* es = entity_of(row, r.entity)) es->reservations.push_back(std::move(r));
        });
  }
  if (loaded) {
    loaded = each_row(
        "SELECT id, entity, start_ns, end_ns, operator, reason FROM locks "
        "ORDER BY entity, start_ns, id",
        "locks", [&](RowReader& row) {
          topology::Lock lock;
          lock.id = row.unsigned_integer(0);
          lock.entity = row.entity(1);
          lock.window = {row.integer(2), row.integer(3)};
          lock.operator_id = row.text(4);
          lock.reason = row.text(5);
          if (EntitySnapshot* es = entity_of(row, lock.entity)) es->locks.push_back(std::move(lock));
        });
  }
  std::optional<std::uint64_t> next_lock_id, next_prepare_id;
  if (loaded) {
    loaded = each_row("SELECT key, value FROM meta", "meta", [&](RowReader& row) {
      const std::string key = row.text(0);
      if (key == "next_lock_id") next_lock_id = row.unsigned_integer(1);
      if (key == "next_prepare_id") next_prepare_id = row.unsigned_integer(1);
    });
  }
  if (loaded && (!next_lock_id || !next_prepare_id)) {
    loaded = unexpected(c.content_error("table meta lacks next_lock_id or next_prepare_id"));
  }
  sqlite3_exec(c.db, "COMMIT", nullptr, nullptr, nullptr);  // a read: nothing to keep
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

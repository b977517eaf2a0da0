// The agents' SQLite files; see database.hpp.

#include "agents/sqlite/database.hpp"

#include <algorithm>
#include <exception>
#include <utility>

namespace drover::sqlite {

namespace fs = std::filesystem;

namespace {

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

Statement::Statement(Statement&& other) noexcept : statement_(std::exchange(other.statement_, nullptr)) {}
Statement& Statement::operator=(Statement&& other) noexcept {
  std::swap(statement_, other.statement_);
  return *this;
}
Statement::~Statement() { sqlite3_finalize(statement_); }

std::int64_t RowReader::integer(int column) {
  if (sqlite3_column_type(statement_, column) != SQLITE_INTEGER) {
    complain(column, "is not an integer");
    return 0;
  }
  return sqlite3_column_int64(statement_, column);
}

std::uint32_t RowReader::small(int column, std::uint32_t limit) {
  const std::int64_t value = integer(column);
  if (value < 0 || value > std::int64_t{limit}) {
    complain(column, "is out of range (" + std::to_string(value) + ")");
    return 0;
  }
  return static_cast<std::uint32_t>(value);
}

std::string RowReader::text(int column) {
  if (sqlite3_column_type(statement_, column) != SQLITE_TEXT) {
    complain(column, "is not text");
    return {};
  }
  return reinterpret_cast<const char*>(sqlite3_column_text(statement_, column));
}

void RowReader::complain(int column, const std::string& problem) {
  complain(std::string("column ") + sqlite3_column_name(statement_, column) + " " + problem);
}

void RowReader::complain(const std::string& problem) {
  if (!error_) {
    error_ = Error{ErrorCode::parse,
                   where_ + ": table " + std::string(table_) + " row " + std::to_string(row_) + ": " + problem};
  }
}

struct Database::Connection {
  fs::path file;
  std::string kind;
  sqlite3* db = nullptr;

  // Statements prepared by the owner are destroyed before this; close_v2 waits for any left.
  ~Connection() { sqlite3_close_v2(db); }
};

Database::Database(std::unique_ptr<Connection> connection) : connection_(std::move(connection)) {}
Database::Database(Database&&) noexcept = default;
Database& Database::operator=(Database&&) noexcept = default;
Database::~Database() = default;

const fs::path& Database::file() const noexcept { return connection_->file; }

std::string Database::where() const { return connection_->kind + " " + connection_->file.string(); }

Error Database::error(int sqlite_code, const std::string& what) const {
  if ((sqlite_code & 0xff) == SQLITE_BUSY) {
    return Error{ErrorCode::unavailable,
                 where() + " is in use by another process (" + what + ": " + sqlite3_errmsg(connection_->db) + ")"};
  }
  return Error{code_of(sqlite_code), where() + ": " + what + ": " + sqlite3_errmsg(connection_->db)};
}

Error Database::content_error(const std::string& message) const {
  return Error{ErrorCode::parse, where() + ": " + message};
}

Status Database::exec(const char* sql, const std::string& what) {
  const int rc = sqlite3_exec(connection_->db, sql, nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) return unexpected(error(rc, what));
  return {};
}

Result<Statement> Database::prepare(const char* sql, const std::string& what) {
  sqlite3_stmt* statement = nullptr;
  const int rc = sqlite3_prepare_v3(connection_->db, sql, -1, SQLITE_PREPARE_PERSISTENT, &statement, nullptr);
  if (rc != SQLITE_OK) return unexpected(error(rc, what));
  return Statement(statement);
}

Status Database::run(const Statement& statement, std::initializer_list<Value> values, const std::string& what) {
  sqlite3_stmt* s = statement.get();
  int rc = SQLITE_OK;
  int index = 1;
  for (const Value& value : values) {
    if (rc != SQLITE_OK) break;
    if (const auto* number = std::get_if<std::int64_t>(&value)) {
      rc = sqlite3_bind_int64(s, index, *number);
    } else if (const auto* text = std::get_if<std::string_view>(&value)) {
      rc = sqlite3_bind_text(s, index, text->data(), static_cast<int>(text->size()), SQLITE_TRANSIENT);
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

namespace {

/// `statement` stepped to its first row: true on a row, false when it has none.
Result<bool> on_first_row(const Database& db, const Statement& statement, const std::string& what) {
  const int rc = sqlite3_step(statement.get());
  if (rc == SQLITE_DONE) return false;
  if (rc != SQLITE_ROW) return unexpected(db.error(rc, what));
  return true;
}

}  // namespace

Result<std::optional<std::string>> Database::first_text(const char* sql, const std::string& what) {
  auto statement = prepare(sql, what);
  if (!statement) return unexpected(std::move(statement).error());
  const auto row = on_first_row(*this, *statement, what);
  if (!row) return unexpected(row.error());
  if (!*row) return std::optional<std::string>();
  const auto* text = sqlite3_column_text(statement->get(), 0);
  return std::optional<std::string>(text ? reinterpret_cast<const char*>(text) : "");
}

Result<std::optional<std::int64_t>> Database::first_integer(const char* sql, const std::string& what) {
  auto statement = prepare(sql, what);
  if (!statement) return unexpected(std::move(statement).error());
  const auto row = on_first_row(*this, *statement, what);
  if (!row) return unexpected(row.error());
  if (!*row) return std::optional<std::int64_t>();
  if (sqlite3_column_type(statement->get(), 0) != SQLITE_INTEGER) {
    return unexpected(content_error(what + ": not an integer"));
  }
  return std::optional<std::int64_t>(sqlite3_column_int64(statement->get(), 0));
}

Status Database::each_row(const char* sql, const char* table, const std::function<void(RowReader&)>& read) {
  auto statement = prepare(sql, std::string("read table ") + table);
  if (!statement) return unexpected(std::move(statement).error());
  RowReader row(where(), statement->get(), table);
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(statement->get())) == SQLITE_ROW) {
    row.next_row();
    read(row);
    if (row.error()) return unexpected(*row.error());
  }
  if (rc != SQLITE_DONE) return unexpected(error(rc, std::string("read table ") + table));
  return {};
}

Status Database::transaction(const std::string& what, const std::function<Status()>& body) {
  if (Status ok = exec("BEGIN IMMEDIATE", "start " + what); !ok) return ok;
  Status done;
  try {
    done = body();
  } catch (const std::exception& e) {  // never left open: every later transaction would fail
    done = fail(ErrorCode::internal, where() + ": " + what + ": " + e.what());
  }
  if (done) done = exec("COMMIT", "commit " + what);
  if (!done) sqlite3_exec(connection_->db, "ROLLBACK", nullptr, nullptr, nullptr);
  return done;
}

Status Database::read_transaction(const std::string& what, const std::function<Status()>& body) {
  if (Status ok = exec("BEGIN", "start " + what); !ok) return ok;
  Status done = body();
  sqlite3_exec(connection_->db, "COMMIT", nullptr, nullptr, nullptr);  // a read: nothing to keep
  return done;
}

namespace {

/// Creates the schema in an empty database, or checks an existing one.
Status initialize_or_check(Database& db, const Schema& schema, std::string_view key) {
  const auto tables = db.first_integer("SELECT count(*) FROM sqlite_schema", "read the schema");
  if (!tables) return unexpected(tables.error());
  const std::string key_name(schema.key_name);
  if (**tables == 0) {
    if (Status created = db.exec(std::string(schema.sql).c_str(), "create the schema"); !created) return created;
    const std::string fill = "INSERT INTO schema_version VALUES (" + std::to_string(schema.version) + ");" +
                             std::string(schema.fill_sql);
    if (Status filled = db.exec(fill.c_str(), "fill the schema"); !filled) return filled;
    auto insert_key = db.prepare("INSERT INTO meta VALUES (?, ?)", "record the owner");
    if (!insert_key) return unexpected(insert_key.error());
    return db.run(*insert_key, {std::string_view(key_name), key}, "record the owner");
  }
  const auto has_version = db.first_integer(
      "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name = 'schema_version'", "read the schema");
  if (!has_version) return unexpected(has_version.error());
  if (**has_version == 0) {
    return unexpected(db.content_error("an SQLite database but not a Drover " + std::string(schema.kind) +
                                       " (no schema_version table)"));
  }
  const auto version = db.first_integer("SELECT version FROM schema_version", "read the schema version");
  if (!version) return unexpected(version.error());
  if (!*version || **version != schema.version) {
    return unexpected(db.content_error("schema version " +
                                       (*version ? std::to_string(**version) : std::string("missing")) +
                                       ", this build reads version " + std::to_string(schema.version)));
  }
  const std::string query = "SELECT value FROM meta WHERE key = '" + key_name + "'";
  const auto stored_key = db.first_text(query.c_str(), "read the " + key_name);
  if (!stored_key) return unexpected(stored_key.error());
  if (!*stored_key) {
    return unexpected(db.content_error("no " + key_name + " in table meta: not a Drover " +
                                       std::string(schema.kind)));
  }
  if (**stored_key != key) {
    return fail(ErrorCode::conflict, db.where() + " belongs to " + **stored_key + ", not to " + std::string(key) +
                                         " (move it away to start this one afresh)");
  }
  return {};
}

}  // namespace

Result<Database> Database::open(const fs::path& file, const Schema& schema, std::string_view key) {
  auto c = std::make_unique<Connection>();
  c->file = file;
  c->kind = schema.kind;
  const int rc = sqlite3_open_v2(file.c_str(), &c->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  if (rc != SQLITE_OK) {
    std::error_code ignored;
    const std::string hint = fs::is_directory(file, ignored) ? " (it is a directory)"
                             : !fs::is_directory(file.parent_path().empty() ? "." : file.parent_path(), ignored)
                                 ? " (its directory does not exist)"
                                 : "";
    return fail(ErrorCode::io, c->kind + " " + file.string() + ": cannot open or create it: " +
                                   (c->db ? sqlite3_errmsg(c->db) : sqlite3_errstr(rc)) + hint);
  }
  sqlite3_extended_result_codes(c->db, 1);
  Database db(std::move(c));
  sqlite3* handle = db.connection_->db;
  if (sqlite3_db_readonly(handle, "main") == 1) {  // SQLite falls back to reading silently
    return fail(ErrorCode::io, db.where() + ": cannot open it for writing (read-only file)");
  }
  // Exclusive first: entering WAL mode under it keeps the WAL index in process memory and
  // the file locked for as long as it is open.
  if (Status ok = db.exec("PRAGMA locking_mode = EXCLUSIVE", "set the locking mode"); !ok) {
    return unexpected(std::move(ok).error());
  }
  const auto mode = db.first_text("PRAGMA journal_mode = WAL", "switch to WAL mode");
  if (!mode) return unexpected(mode.error());
  if (*mode != "wal") {
    return fail(ErrorCode::io,
                db.where() + ": cannot switch to WAL mode (journal mode " + mode->value_or("unknown") + ")");
  }
  if (Status ok = db.exec("PRAGMA synchronous = FULL", "set synchronous mode"); !ok) {
    return unexpected(std::move(ok).error());
  }
  const auto check = db.first_text("PRAGMA quick_check", "check the database");
  if (!check) return unexpected(check.error());
  if (*check != "ok") {
    std::string report = check->value_or("no answer from quick_check");
    std::replace(report.begin(), report.end(), '\n', ' ');
    return unexpected(db.content_error("damaged: " + report));
  }
  Status ready = db.transaction("the schema", [&] { return initialize_or_check(db, schema, key); });
  if (!ready) return unexpected(std::move(ready).error());
  return db;
}

}  // namespace drover::sqlite

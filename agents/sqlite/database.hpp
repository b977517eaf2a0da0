#pragma once
// The SQLite files agents keep their state in (the topology agent's journal, the logical
// agent's order journal): opened for one process, durable, with a schema version and a key
// naming what the file belongs to, so that a file of another kind, version or owner is
// refused instead of misread. Statements and row readers whose errors are values naming
// the file.

#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "drover/common/result.hpp"

namespace drover::sqlite {

/// Owns a prepared statement.
class Statement {
 public:
  Statement() = default;
  explicit Statement(sqlite3_stmt* statement) : statement_(statement) {}
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&& other) noexcept;
  ~Statement();
  sqlite3_stmt* get() const noexcept { return statement_; }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

/// A value bound to a statement parameter.
using Value = std::variant<std::nullptr_t, std::int64_t, std::string_view>;

/// Unsigned 64-bit ids are stored as SQLite's signed INTEGER, bit for bit.
inline std::int64_t stored(std::uint64_t value) { return static_cast<std::int64_t>(value); }

/// Reads the columns of one row of a table, checking types and ranges; the first problem is
/// kept as the error (parse, naming the file, table, row and column).
class RowReader {
 public:
  /// \param where  names the file in messages
  RowReader(std::string where, sqlite3_stmt* statement, const char* table)
      : where_(std::move(where)), statement_(statement), table_(table) {}

  void next_row() { ++row_; }
  const std::optional<Error>& error() const { return error_; }

  std::int64_t integer(int column);
  std::uint64_t unsigned_integer(int column) { return static_cast<std::uint64_t>(integer(column)); }
  /// An integer in [0, limit].
  std::uint32_t small(int column, std::uint32_t limit);
  std::string text(int column);
  bool null(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }

  void complain(int column, const std::string& problem);
  void complain(const std::string& problem);

 private:
  std::string where_;
  sqlite3_stmt* statement_;
  const char* table_;
  std::size_t row_ = 0;
  std::optional<Error> error_;
};

/// What a kind of file holds: created in a new (or empty) file, checked in an existing one.
struct Schema {
  /// Names the kind in messages ("journal", "order journal"): "journal FILE: ...".
  std::string_view kind;
  /// CREATE statements; they must create `schema_version (version INTEGER)` and
  /// `meta (key TEXT PRIMARY KEY, value ANY)`.
  std::string_view sql;
  int version = 1;
  /// The meta row naming what the file belongs to.
  std::string_view key_name;
  /// Statements filling a new file (may be empty).
  std::string_view fill_sql;
};

/// One SQLite file, open for one process. Not thread-safe: one thread at a time.
///
/// Durability: WAL mode with synchronous=FULL: a transaction that has committed survives
/// kill -9 (and a power cut); one cut short leaves the file as it was before it.
/// Exclusive: the file stays locked while open (locking_mode=EXCLUSIVE), so a second
/// process started on the same file is refused instead of interleaving its writes.
class Database {
 public:
  /// Opens `file`, creating it with `schema` if it does not exist or is empty.
  /// \param key  what the file belongs to: recorded at creation (meta row schema.key_name),
  ///             and an existing file must carry the same.
  /// \return the database, or an error whose message names the file:
  ///   io            the file cannot be opened or created (missing directory, permissions)
  ///   parse         not an SQLite database, a damaged one, not a Drover file of this kind,
  ///                 or a schema version other than schema.version
  ///   conflict      a file of another owner (another topology, partition, vehicle)
  ///   unavailable   another process has it open
  static Result<Database> open(const std::filesystem::path& file, const Schema& schema, std::string_view key);

  Database(Database&&) noexcept;
  Database& operator=(Database&&) noexcept;
  ~Database();

  const std::filesystem::path& file() const noexcept;
  /// "KIND FILE", how messages name the file.
  std::string where() const;

  /// The error SQLite reported for `what` (SQLITE_BUSY: unavailable, naming the other process).
  Error error(int sqlite_code, const std::string& what) const;
  /// A parse error about the file's content.
  Error content_error(const std::string& message) const;

  Status exec(const char* sql, const std::string& what);
  /// A statement kept for the life of the database.
  Result<Statement> prepare(const char* sql, const std::string& what);
  /// Binds `values` to the statement's parameters in order and runs it to completion.
  Status run(const Statement& statement, std::initializer_list<Value> values, const std::string& what);
  /// The first column of the first row of `sql`, if it has a row.
  Result<std::optional<std::string>> first_text(const char* sql, const std::string& what);
  Result<std::optional<std::int64_t>> first_integer(const char* sql, const std::string& what);
  /// Runs `sql`, handing each row to `read`; stops at the first reader or SQLite error.
  Status each_row(const char* sql, const char* table, const std::function<void(RowReader&)>& read);
  /// Runs `body` in one write transaction (BEGIN IMMEDIATE): committed when it succeeds,
  /// rolled back when it or the commit fails, or it throws (internal, with its message).
  Status transaction(const std::string& what, const std::function<Status()>& body);
  /// Runs `body` in one read transaction, so that it sees one state of the file.
  Status read_transaction(const std::string& what, const std::function<Status()>& body);

 private:
  struct Connection;
  explicit Database(std::unique_ptr<Connection> connection);
  std::unique_ptr<Connection> connection_;
};

}  // namespace drover::sqlite

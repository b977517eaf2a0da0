// The logical agent's order journal; see order_journal.hpp. The schema:
//   schema_version(version)   one row: kSchemaVersion
//   meta(key, value)          vehicle; paused (the reason) while an operator paused it
//   orders(seq, name, destinations, properties, state, destination, created_ns, started_ns,
//          finished_ns, failure, withdrawal, action_command)
// seq is the arrival order (never reused); destinations and properties are JSON text:
// [{"location": ID, "operation": OP, "properties": {NAME: VALUE}}] and {NAME: VALUE}.

#include "agents/logical_agent/src/order_journal.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "agents/sqlite/database.hpp"
#include "drover/common/identifier.hpp"

namespace drover::logical_agent {

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL) STRICT;
CREATE TABLE meta (key TEXT PRIMARY KEY, value ANY NOT NULL) STRICT;
CREATE TABLE orders (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  name TEXT NOT NULL UNIQUE,
  destinations TEXT NOT NULL,
  properties TEXT NOT NULL,
  state TEXT NOT NULL,
  destination INTEGER NOT NULL,
  created_ns INTEGER NOT NULL,
  started_ns INTEGER,
  finished_ns INTEGER,
  failure TEXT NOT NULL,
  withdrawal TEXT,
  action_command TEXT
) STRICT;
)sql";

constexpr sqlite::Schema kOrderJournalSchema{"order journal", kSchema, OrderJournal::kSchemaVersion, "vehicle", ""};

constexpr std::array kStates{OrderState::queued, OrderState::running, OrderState::finished, OrderState::failed,
                             OrderState::withdrawn};

std::string destinations_json(const std::vector<Destination>& destinations) {
  auto out = nlohmann::json::array();
  for (const Destination& d : destinations) {
    out.push_back({{"location", d.location_id}, {"operation", d.operation}, {"properties", d.properties}});
  }
  return out.dump();  // throws on text that is not UTF-8 (store says so)
}

/// Properties stored as a JSON object of texts, or nullopt for anything else.
std::optional<std::map<std::string, std::string>> parse_properties(const nlohmann::json& json) {
  if (!json.is_object()) return std::nullopt;
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : json.items()) {
    if (!value.is_string()) return std::nullopt;
    out[name] = value.get<std::string>();
  }
  return out;
}

/// The destinations stored by destinations_json, or nullopt for anything else.
std::optional<std::vector<Destination>> parse_destinations(const std::string& text) {
  const auto json = nlohmann::json::parse(text, nullptr, false);
  if (!json.is_array() || json.empty()) return std::nullopt;
  std::vector<Destination> out;
  for (const auto& item : json) {
    if (!item.is_object() || !item.contains("location") || !item["location"].is_string() ||
        !item.contains("operation") || !item["operation"].is_string() || !item.contains("properties")) {
      return std::nullopt;
    }
    auto properties = parse_properties(item["properties"]);
    if (!properties) return std::nullopt;
    out.push_back(Destination{topology::kNoEntity, item["location"].get<std::string>(),
                              item["operation"].get<std::string>(), std::move(*properties)});
  }
  return out;
}

sqlite::Value optional_time(const std::optional<TimeNs>& time) {
  if (time) return std::int64_t{*time};
  return nullptr;
}
sqlite::Value optional_text(const std::optional<std::string>& text) {
  if (text) return std::string_view(*text);
  return nullptr;
}

}  // namespace

struct OrderJournal::Connection {
  sqlite::Database db;
  std::size_t ended_kept;
  // Declared after db: finalized before it closes.
  sqlite::Statement forget_name, upsert, forget_ended, pause, resume;

  Connection(sqlite::Database database, std::size_t kept) : db(std::move(database)), ended_kept(kept) {}

  Status prepare_statements() {
    const std::pair<sqlite::Statement*, const char*> statements[] = {
        {&forget_name, "DELETE FROM orders WHERE name = ?"},
        {&upsert,
         "INSERT INTO orders (name, destinations, properties, state, destination, created_ns, started_ns, "
         "finished_ns, failure, withdrawal, action_command) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) "
         "ON CONFLICT (name) DO UPDATE SET destinations = excluded.destinations, properties = excluded.properties, "
         "state = excluded.state, destination = excluded.destination, created_ns = excluded.created_ns, "
         "started_ns = excluded.started_ns, finished_ns = excluded.finished_ns, failure = excluded.failure, "
         "withdrawal = excluded.withdrawal, action_command = excluded.action_command"},
        {&pause,
         "INSERT INTO meta (key, value) VALUES ('paused', ?) ON CONFLICT (key) DO UPDATE SET value = excluded.value"},
        {&resume, "DELETE FROM meta WHERE key = 'paused'"},
        {&forget_ended,
         "DELETE FROM orders WHERE seq IN (SELECT seq FROM orders WHERE state IN ('finished', 'failed', "
         "'withdrawn') ORDER BY seq DESC LIMIT -1 OFFSET ?)"},
    };
    for (const auto& [statement, sql] : statements) {
      auto prepared = db.prepare(sql, "prepare the statements");
      if (!prepared) return unexpected(std::move(prepared).error());
      *statement = std::move(*prepared);
    }
    return {};
  }

  Status store(const Order& order) {
    std::string destinations, properties;
    try {
      destinations = destinations_json(order.destinations);
      properties = nlohmann::json(order.properties).dump();
    } catch (const nlohmann::json::exception& e) {
      return fail(ErrorCode::invalid_argument,
                  db.where() + ": order '" + order.name + "' cannot be stored: its operations or properties hold "
                  "text that is not UTF-8 (" + e.what() + ")");
    }
    return db.run(upsert,
                  {std::string_view(order.name), std::string_view(destinations), std::string_view(properties),
                   std::string_view(to_string(order.state)), static_cast<std::int64_t>(order.destination),
                   std::int64_t{order.created}, optional_time(order.started), optional_time(order.finished),
                   std::string_view(order.failure), optional_text(order.withdrawal),
                   optional_text(order.action_command)},
                  "store order '" + order.name + "'");
  }
};

OrderJournal::OrderJournal(std::unique_ptr<Connection> connection) : connection_(std::move(connection)) {}
OrderJournal::OrderJournal(OrderJournal&&) noexcept = default;
OrderJournal& OrderJournal::operator=(OrderJournal&&) noexcept = default;
OrderJournal::~OrderJournal() = default;

const std::filesystem::path& OrderJournal::file() const noexcept { return connection_->db.file(); }

Result<OrderJournal> OrderJournal::open(const std::filesystem::path& file, std::string_view vehicle,
                                        std::size_t ended_kept) {
  auto db = sqlite::Database::open(file, kOrderJournalSchema, "vehicle '" + std::string(vehicle) + "'");
  if (!db) return unexpected(std::move(db).error());
  auto c = std::make_unique<Connection>(std::move(*db), ended_kept);
  if (Status ok = c->prepare_statements(); !ok) return unexpected(std::move(ok).error());
  return OrderJournal(std::move(c));
}

Status OrderJournal::add(const Order& order) {
  Connection& c = *connection_;
  return c.db.transaction("storing order '" + order.name + "'", [&]() -> Status {
    // A row of the same name is an order the agent forgot: the new one goes last, not in its place.
    if (Status ok = c.db.run(c.forget_name, {std::string_view(order.name)}, "replace order '" + order.name + "'"); !ok) {
      return ok;
    }
    return c.store(order);
  });
}

Status OrderJournal::update(const Order& order) {
  Connection& c = *connection_;
  return c.db.transaction("storing order '" + order.name + "'", [&]() -> Status {
    if (Status ok = c.store(order); !ok) return ok;
    if (is_open(order.state)) return {};
    return c.db.run(c.forget_ended, {static_cast<std::int64_t>(c.ended_kept)}, "forget the oldest ended orders");
  });
}

Status OrderJournal::store_pause(const std::optional<std::string>& reason) {
  Connection& c = *connection_;
  if (!reason) return c.db.run(c.resume, {}, "store the resume");
  return c.db.run(c.pause, {std::string_view(*reason)}, "store the pause");
}

Result<std::optional<std::string>> OrderJournal::load_pause() {
  Connection& c = *connection_;
  auto type = c.db.first_text("SELECT typeof(value) FROM meta WHERE key = 'paused'", "load the pause");
  if (!type) return unexpected(std::move(type).error());
  if (!*type) return std::optional<std::string>();
  if (**type != "text") return unexpected(c.db.content_error("table meta, row 'paused': the reason is not text"));
  return c.db.first_text("SELECT value FROM meta WHERE key = 'paused'", "load the pause");
}

Result<std::vector<Order>> OrderJournal::load() {
  Connection& c = *connection_;
  std::vector<Order> orders;
  bool running_seen = false;
  Status loaded = c.db.read_transaction("loading", [&] {
    return c.db.each_row(
        "SELECT name, destinations, properties, state, destination, created_ns, started_ns, finished_ns, failure, "
        "withdrawal, action_command FROM orders ORDER BY seq",
        "orders", [&](sqlite::RowReader& row) {
          Order order;
          order.name = row.text(0);
          // Names are keys on the wire, whose size Fast DDS bounds: one that make_order
          // would refuse (written by hand, or by an older version) must not stop the agent
          // when it is first published.
          if (auto valid = check_identifier(order.name, "order name"); !valid) {
            row.complain(0, "is not a valid order name: " + valid.error().message);
          }
          if (auto destinations = parse_destinations(row.text(1))) {
            order.destinations = std::move(*destinations);
          } else {
            row.complain(1, "is not a list of destinations");
          }
          if (auto properties = parse_properties(nlohmann::json::parse(row.text(2), nullptr, false))) {
            order.properties = std::move(*properties);
          } else {
            row.complain(2, "is not an object of text properties");
          }
          const std::string state = row.text(3);
          const auto known = std::find_if(kStates.begin(), kStates.end(),
                                          [&](OrderState s) { return state == to_string(s); });
          if (known == kStates.end()) {
            row.complain(3, "is not an order state ('" + state + "')");
          } else {
            order.state = *known;
          }
          order.destination = row.small(4, std::numeric_limits<std::uint32_t>::max());
          // Queued and running orders are at a destination; a finished one is past its last.
          const std::size_t limit = order.destinations.size() - (!is_open(order.state) ? 0 : 1);
          if (!order.destinations.empty() && order.destination > limit) {
            row.complain(4, "is out of range (" + std::to_string(order.destination) + " of " +
                                std::to_string(order.destinations.size()) + " destinations)");
          }
          order.created = row.integer(5);
          if (!row.null(6)) order.started = row.integer(6);
          if (!row.null(7)) order.finished = row.integer(7);
          order.failure = row.text(8);
          if (!row.null(9)) order.withdrawal = row.text(9);
          if (!row.null(10)) order.action_command = row.text(10);
          if (order.state == OrderState::running) {
            if (running_seen) row.complain(3, "is 'running' for a second order");
            running_seen = true;
          }
          orders.push_back(std::move(order));
        });
  });
  if (!loaded) return unexpected(std::move(loaded).error());
  return orders;
}

}  // namespace drover::logical_agent

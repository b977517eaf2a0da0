#include "drover/launcher/launch_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "agents/cli/number_checks.hpp"
#include "agents/cli/text_checks.hpp"
#include "drover/carp/vehicle_profile_json.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/identifier.hpp"
#include "drover/common/json_document.hpp"
#include "drover/common/text_file.hpp"
#include "drover/dds/participant.hpp"
#include "drover/launcher/load_generator.hpp"
#include "drover/ran/sim_vehicle.hpp"
#include "drover/logical_agent/charging.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::launcher {

namespace {

using Json = nlohmann::json;

/// What a field's value must be, and how it becomes a command-line value.
enum class FieldType {
  log_level,        ///< one of the agents' log levels (cli::is_log_level)
  vertex,           ///< the id of a vertex of the topology
  vertex_list,      ///< a non-empty array of vertex ids (one option per id)
  partition,        ///< a partition named by the topology
  number,           ///< a number in [least, most]
  positive_number,  ///< a number in (0, most]
  count,            ///< an integer in [least, most]
  flag,             ///< true adds the option without a value; false leaves it out
  journal,          ///< a file path; relative ones are relative to the state directory
};

/// The ranges are the ones the subcommand's option takes (agents/cli/number_checks.hpp):
/// a value it would refuse is refused in the file, so that nothing is started.
struct FieldRule {
  std::string_view key;
  std::string_view option;  ///< the subcommand's option it becomes
  FieldType type;
  double least = 0;                           ///< number, count
  double most = cli::kLargestOptionValue;     ///< number, positive_number, count
};

constexpr double kLargest = cli::kLargestOptionValue;

/// The value of a JSON integer that int64 holds, else nullopt (a float, or an unsigned
/// number beyond int64).
std::optional<std::int64_t> json_integer(const Json& value) {
  if (!value.is_number_integer()) return std::nullopt;
  if (value.is_number_unsigned() && value.get<std::uint64_t>() > std::uint64_t{INT64_MAX}) return std::nullopt;
  return value.get<std::int64_t>();
}
constexpr auto kLargestWhole = static_cast<double>(cli::kLargestWholeOption);

/// The fields a vehicle profile may set, and the ran-sim options they become (none: the
/// field is for the logical agent only).
const std::vector<FieldRule> kProfileFields{
    {"length", "", FieldType::positive_number},
    {"width", "", FieldType::positive_number},
    {"max_speed", "--max-speed", FieldType::positive_number},
    {"acceleration", "--acceleration", FieldType::positive_number},
    {"deceleration", "--deceleration", FieldType::positive_number},
    {"angular_speed", "--angular-speed", FieldType::positive_number},
    {"battery_capacity", "--battery-capacity", FieldType::positive_number},
    {"battery", "--battery", FieldType::number},
    {"drain", "--drain", FieldType::number},
    {"charge_rate", "--charge-rate", FieldType::number},
    {"load_duration", "--load-duration", FieldType::number},
    {"unload_duration", "--unload-duration", FieldType::number},
};

/// The profile fields a logical agent plans with (its --vehicle file, carp's format), so
/// that it plans with the speeds its simulated vehicle drives at.
const std::vector<std::string_view> kLogicalProfileFields{"max_speed", "acceleration", "deceleration",
                                                          "length", "width"};

struct KindRules {
  AgentKind kind;
  std::string_view name;
  std::string_view subcommand;
  std::string_view id_option;       ///< the option that sets the agent id
  std::string_view vehicle_option;  ///< the option that sets the vehicle id; empty: none
  bool takes_profile;               ///< ran-sim, logical: may name a vehicle profile
  bool takes_topology;              ///< gets --topology FILE
  std::vector<FieldRule> fields;    ///< besides kind, id, vehicle, restart, max_restarts
};

const std::vector<KindRules>& kind_rules() {
  static const std::vector<KindRules> rules{
      {AgentKind::topology, "topology", "topology-agent", "--id", "", false, true,
       {{"partition", "--partition", FieldType::partition},
        {"db", "--db", FieldType::journal},
        {"departed_after", "--departed-after", FieldType::number},
        {"log_level", "--log-level", FieldType::log_level}}},
      {AgentKind::ran_sim, "ran-sim", "ran-sim", "--agent-id", "--id", true, true,
       {{"at", "--at", FieldType::vertex},
        {"heading", "--heading", FieldType::number, -1000, 1000},
        {"loaded", "--loaded", FieldType::flag},
        {"status_period_ms", "--status-period-ms", FieldType::count, 1, 60000},
        {"log_level", "--log-level", FieldType::log_level}}},
      {AgentKind::routing, "routing", "routing-agent", "--id", "", false, false,
       {{"log_level", "--log-level", FieldType::log_level}}},
      {AgentKind::logical, "logical", "logical-agent", "--id", "", true, true,
       {{"lookahead", "--lookahead", FieldType::count, 1, 1000},
        {"delay_threshold", "--delay-threshold", FieldType::positive_number},
        {"park_after", "--park-after", FieldType::number, -kLargest, kLargest},
        {"charge_below", "--charge-below", FieldType::number, 0, 1},
        {"charge_to", "--charge-to", FieldType::positive_number, 0, 1},
        {"error_limit", "--error-limit", FieldType::positive_number},
        {"route_limit", "--route-limit", FieldType::number},
        {"wait_alarm", "--wait-alarm", FieldType::number},
        {"db", "--db", FieldType::journal},
        {"log_level", "--log-level", FieldType::log_level}}},
      {AgentKind::load_generator, "load-generator", "load-generator", "--id", "", false, true,
       {{"seed", "--seed", FieldType::count, 0, kLargestWhole},
        {"stations", "--station", FieldType::vertex_list},
        {"max_orders", "--max-orders", FieldType::count, 0, kLargestWhole},
        {"log_level", "--log-level", FieldType::log_level}}},
  };
  return rules;
}

const KindRules* find_kind(std::string_view name) {
  for (const auto& rules : kind_rules()) {
    if (rules.name == name) return &rules;
  }
  return nullptr;
}

const KindRules& rules_of(AgentKind kind) {
  for (const auto& rules : kind_rules()) {
    if (rules.kind == kind) return rules;
  }
  return kind_rules().front();  // unreachable: every kind has rules
}

std::string kind_list() {
  std::string list;
  for (const auto& rules : kind_rules()) list += (list.empty() ? "" : ", ") + std::string(rules.name);
  return list;
}

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

/// Collects the problems of one launch file while it is checked.
class Checker {
 public:
  void problem(std::string where, std::string what) {
    problems_.push_back({std::move(where), std::move(what)});
  }
  LaunchProblems take() { return std::move(problems_); }
  bool clean() const { return problems_.empty(); }

 private:
  LaunchProblems problems_;
};

class LaunchFileParser {
 public:
  LaunchFileParser(const std::filesystem::path& path, const std::filesystem::path& state_dir)
      : state_dir_(state_dir) {
    file_.path = path;
  }

  Result<LaunchFile, LaunchProblems> parse(std::string_view text) {
    auto document = parse_json_document<Json>(text);
    if (!document) {
      for (auto& problem : document.error()) checker_.problem(std::move(problem.where), std::move(problem.what));
      return unexpected(checker_.take());
    }
    const Json& root = *document;
    if (!root.is_object()) {
      checker_.problem("", "the launch file must be a JSON object");
      return unexpected(checker_.take());
    }
    reject_unknown_keys(root, "", {"name", "domain", "time_factor", "epoch", "topology",
                                   "vehicle_profiles", "agents"});
    read_header(root);
    read_profiles(root);
    if (const auto agents = root.find("agents"); agents == root.end()) {
      checker_.problem("agents", "missing: the list of agents to start");
    } else if (!agents->is_array() || agents->empty()) {
      checker_.problem("agents", "must be a non-empty array of agent entries");
    } else {
      for (std::size_t index = 0; index < agents->size(); ++index) {
        read_agent((*agents)[index], "agents[" + std::to_string(index) + "]");
      }
      check_fleet();
    }
    if (!checker_.clean()) return unexpected(checker_.take());
    return std::move(file_);
  }

 private:
  void reject_unknown_keys(const Json& object, const std::string& where,
                           std::initializer_list<std::string_view> known) {
    for (const auto& [key, value] : object.items()) {
      bool found = false;
      for (auto name : known) found = found || name == key;
      if (!found) checker_.problem(join(where, key), "unknown field");
    }
  }

  static std::string join(const std::string& where, std::string_view key) {
    return where.empty() ? std::string(key) : where + "." + std::string(key);
  }

  void read_header(const Json& root) {
    if (auto name = root.find("name"); name != root.end()) {
      if (name->is_string()) file_.name = name->get<std::string>();
      else checker_.problem("name", "must be a string");
    }
    if (auto domain = root.find("domain"); domain != root.end()) {
      if (domain->is_number_integer() && domain->get<std::int64_t>() >= 0 &&
          domain->get<std::int64_t>() <= 232) {
        file_.domain_id = domain->get<std::uint32_t>();
      } else {
        checker_.problem("domain", "must be an integer DDS domain id in 0..232");
      }
    }
    if (auto factor = root.find("time_factor"); factor != root.end()) {
      if (factor->is_number() && factor->get<double>() > 0 && factor->get<double>() <= kMaxTimeFactor) {
        file_.time_factor = factor->get<double>();
      } else {
        checker_.problem("time_factor", fmt::format("must be a number > 0 and at most {} (shared-clock "
                                                    "seconds per real second)", kMaxTimeFactor));
      }
    }
    if (auto epoch = root.find("epoch"); epoch != root.end()) {
      if (const auto ns = json_integer(*epoch); ns && *ns >= 0 && *ns <= kLatestTime) {
        file_.epoch_ns = *ns;
      } else if (!(epoch->is_string() && epoch->get<std::string>() == "now")) {
        checker_.problem("epoch", fmt::format("must be \"now\" or an integer from 0 to {} (shared-clock "
                                              "nanoseconds at start)", kLatestTime));
      }
    }
    const auto topology = root.find("topology");
    if (topology == root.end() || !topology->is_string() || topology->get<std::string>().empty()) {
      checker_.problem("topology", "missing or not a string: the topology file (relative to the launch file)");
      return;
    }
    std::filesystem::path topology_path = topology->get<std::string>();
    if (topology_path.is_relative()) topology_path = file_.path.parent_path() / topology_path;
    file_.topology_file = std::filesystem::absolute(topology_path).lexically_normal();
    auto loaded = topology::load_topology_file(file_.topology_file);
    if (!loaded) {
      for (const auto& problem : loaded.error()) {
        checker_.problem("topology",
                         topology::diagnostic_text(file_.topology_file.string(), problem));
      }
      return;
    }
    topology_ = std::move(*loaded);
  }

  void read_profiles(const Json& root) {
    const auto profiles = root.find("vehicle_profiles");
    if (profiles == root.end()) return;
    if (!profiles->is_object()) {
      checker_.problem("vehicle_profiles", "must be an object of named profiles");
      return;
    }
    for (const auto& [name, profile] : profiles->items()) {
      const std::string where = "vehicle_profiles." + name;
      if (!profile.is_object()) {
        checker_.problem(where, "must be an object");
        continue;
      }
      Profile parsed;
      parsed.logical = Json::object();
      for (const auto& [key, value] : profile.items()) {
        const FieldRule* rule = nullptr;
        for (const auto& candidate : kProfileFields) {
          if (candidate.key == key) rule = &candidate;
        }
        if (rule == nullptr) {
          checker_.problem(join(where, key), "unknown field (expected one of: " + profile_field_list() + ")");
          continue;
        }
        std::vector<std::string> checked;
        add_option(*rule, value, join(where, key), checked);
        if (checked.empty()) continue;  // reported
        if (!rule->option.empty()) parsed.ran_options.insert(parsed.ran_options.end(), checked.begin(), checked.end());
        if (std::find(kLogicalProfileFields.begin(), kLogicalProfileFields.end(), key) != kLogicalProfileFields.end()) {
          parsed.logical[key] = value;
        }
      }
      // The planner's bounds, checked here so that no logical agent is started to refuse it.
      if (auto vehicle = carp::vehicle_profile_from_json(parsed.logical); !vehicle) {
        checker_.problem(where, vehicle.error().message);
      }
      // The simulated vehicle starts with a full battery unless told otherwise, and never
      // with more than it holds.
      const auto battery = profile.find("battery");
      const auto capacity = profile.find("battery_capacity");
      const double holds = capacity != profile.end() && capacity->is_number() ? capacity->get<double>()
                                                                              : ran::SimVehicleConfig{}.battery_capacity_wh;
      if (battery != profile.end() && battery->is_number() && battery->get<double>() > holds) {
        checker_.problem(join(where, "battery"), fmt::format("must be at most the battery capacity ({} Wh)", holds));
      }
      profiles_[name] = std::move(parsed);
    }
  }

  static std::string profile_field_list() {
    std::string list;
    for (const auto& rule : kProfileFields) list += (list.empty() ? "" : ", ") + std::string(rule.key);
    return list;
  }

  void read_agent(const Json& entry, const std::string& where) {
    if (!entry.is_object()) {
      checker_.problem(where, "must be an object");
      return;
    }
    const auto kind = entry.find("kind");
    if (kind == entry.end() || !kind->is_string()) {
      checker_.problem(join(where, "kind"), "missing: one of " + kind_list());
      return;
    }
    const KindRules* rules = find_kind(kind->get<std::string>());
    if (rules == nullptr) {
      checker_.problem(join(where, "kind"), "unknown kind '" + kind->get<std::string>() +
                                                "' (expected one of " + kind_list() + ")");
      return;
    }
    AgentEntry agent;
    agent.kind = rules->kind;
    std::optional<Json> logical_profile;
    const bool has_vehicle = rules->kind == AgentKind::ran_sim || rules->kind == AgentKind::logical;
    for (const auto& [key, value] : entry.items()) {
      const std::string field = join(where, key);
      if (key == "kind") continue;
      if (key == "id" || (key == "vehicle" && has_vehicle)) {
        if (!value.is_string() || value.get<std::string>().empty()) {
          checker_.problem(field, "must be a non-empty string");
        } else {
          (key == "id" ? agent.id : agent.vehicle) = value.get<std::string>();
        }
      } else if (key == "restart") {
        if (value == "never") agent.restart = RestartPolicy::never;
        else if (value == "on-failure") agent.restart = RestartPolicy::on_failure;
        else checker_.problem(field, "must be \"never\" or \"on-failure\"");
      } else if (key == "max_restarts") {
        if (value.is_number_integer() && value.get<std::int64_t>() >= 0 && value.get<std::int64_t>() <= 1000) {
          agent.max_restarts = value.get<int>();
        } else {
          checker_.problem(field, "must be an integer in 0..1000");
        }
      } else if (key == "profile" && rules->takes_profile) {
        const auto profile = value.is_string() ? profiles_.find(value.get<std::string>()) : profiles_.end();
        if (profile == profiles_.end()) {
          checker_.problem(field, "names no entry of vehicle_profiles");
        } else if (rules->kind == AgentKind::ran_sim) {
          agent.options.insert(agent.options.end(), profile->second.ran_options.begin(),
                               profile->second.ran_options.end());
        } else {
          logical_profile = profile->second.logical;
        }
      } else {
        const FieldRule* rule = nullptr;
        for (const auto& candidate : rules->fields) {
          if (candidate.key == key) rule = &candidate;
        }
        if (rule == nullptr) {
          checker_.problem(field, "unknown field for kind '" + std::string(rules->name) + "'");
        } else {
          add_option(*rule, value, field, agent.options, &agent.journals);
        }
      }
    }
    if (has_vehicle && agent.vehicle.empty()) {
      checker_.problem(join(where, "vehicle"), "missing: the vehicle id");
    } else if (has_vehicle) {
      // The subcommand takes it as an id (a DDS key): refused there, the agent would not start.
      if (auto problem = identifier_problem(agent.vehicle)) {
        checker_.problem(join(where, "vehicle"), "'" + printable_identifier(agent.vehicle) + "' " + *problem);
      }
    }
    if (rules->kind == AgentKind::ran_sim && !entry.contains("at")) {
      checker_.problem(join(where, "at"), "missing: the vertex the vehicle starts at");
    }
    if (rules->kind == AgentKind::logical) check_charging(entry, where);
    if (rules->kind == AgentKind::load_generator) check_stations(entry, where);
    if (rules->kind == AgentKind::logical && !agent.id.empty() && agent.id != agent.vehicle) {
      checker_.problem(join(where, "id"), "a logical agent's id is its vehicle id: leave it out");
    }
    if (agent.id.empty()) agent.id = default_id(*rules, agent, entry);
    if (auto valid = dds::validate_agent_id(agent.id); !valid) {
      checker_.problem(join(where, "id"), valid.error().message);
    }
    // Identity and topology first, then the entry's own options.
    std::vector<std::string> identity{std::string(rules->id_option), agent.id};
    if (!rules->vehicle_option.empty()) {
      identity.insert(identity.end(), {std::string(rules->vehicle_option), agent.vehicle});
    }
    if (rules->takes_topology) identity.insert(identity.end(), {"--topology", file_.topology_file.string()});
    agent.options.insert(agent.options.begin(), identity.begin(), identity.end());
    if (logical_profile && !agent.vehicle.empty()) {
      // The logical agent reads its profile from a file: written into the state directory.
      (*logical_profile)["id"] = agent.vehicle;
      const auto profile_file = (state_dir_ / (agent.vehicle + ".vehicle.json")).lexically_normal();
      agent.files.push_back({profile_file, logical_profile->dump() + "\n"});
      agent.options.insert(agent.options.end(), {"--vehicle", profile_file.string()});
    }
    starts_.push_back(entry.contains("at") && entry["at"].is_string() ? entry["at"].get<std::string>() : "");
    wheres_.push_back(where);
    partitions_.push_back(entry.contains("partition") && entry["partition"].is_string()
                              ? entry["partition"].get<std::string>()
                              : "");
    profile_names_.push_back(entry.contains("profile") && entry["profile"].is_string()
                                 ? entry["profile"].get<std::string>()
                                 : "");
    file_.agents.push_back(std::move(agent));
  }

  /// A logical agent's charging thresholds together, once each is in range (its rule says
  /// what is wrong otherwise).
  void check_charging(const Json& entry, const std::string& where) {
    const auto number_or = [&entry](const char* key, double otherwise) {
      return entry.contains(key) && entry[key].is_number() ? entry[key].get<double>() : otherwise;
    };
    const double below = number_or("charge_below", logical_agent::kDefaultChargeBelow);
    const double to = number_or("charge_to", logical_agent::kDefaultChargeTo);
    if (!(below >= 0 && below <= 1 && to > 0 && to <= 1)) return;
    if (auto problem = logical_agent::charging_problem(below, to)) checker_.problem(join(where, "charge_to"), *problem);
  }

  /// A load generator's stations together: the ones named, or every station of the topology.
  void check_stations(const Json& entry, const std::string& where) {
    std::vector<std::string> stations;
    const auto named = entry.find("stations");
    if (named != entry.end()) {
      if (!named->is_array()) return;  // reported by its rule
      for (const auto& id : *named) {
        if (id.is_string()) stations.push_back(id.get<std::string>());
      }
    } else if (topology_) {
      for (const auto& vertex : topology_->vertices()) {
        if (vertex.kind == topology::VertexKind::station) stations.push_back(vertex.id);
      }
    } else {
      return;  // the topology's own problems are reported already
    }
    if (auto problem = stations_problem(stations)) {
      checker_.problem(join(where, "stations"), named != entry.end()
                                                    ? *problem
                                                    : "the topology's stations: " + *problem + " (name them)");
    }
  }

  static std::string default_id(const KindRules& rules, const AgentEntry& agent, const Json& entry) {
    switch (rules.kind) {
      case AgentKind::topology:
        return entry.contains("partition") && entry["partition"].is_string()
                   ? "topology-" + entry["partition"].get<std::string>()
                   : "topology";
      case AgentKind::ran_sim: return "ran-" + agent.vehicle;
      case AgentKind::logical: return agent.vehicle;
      case AgentKind::routing: return "routing";
      case AgentKind::load_generator: return "load-generator";
    }
    return "agent";
  }

  /// Adds the option `rule` makes of `value` to `options` (a journal's path also to
  /// `journals`, when given), or reports why it cannot.
  void add_option(const FieldRule& rule, const Json& value, const std::string& where,
                  std::vector<std::string>& options, std::vector<std::filesystem::path>* journals = nullptr) {
    const std::string option(rule.option);
    switch (rule.type) {
      case FieldType::log_level:
        if (!value.is_string() || !cli::is_log_level(value.get<std::string>())) {
          return checker_.problem(where, "must be one of \"trace\", \"debug\", \"info\", \"warn\", \"error\", \"off\"");
        }
        options.insert(options.end(), {option, value.get<std::string>()});
        return;
      case FieldType::vertex:
        if (!value.is_string()) return checker_.problem(where, "must be a vertex id (a string)");
        if (check_vertex(value.get<std::string>(), where)) {
          options.insert(options.end(), {option, value.get<std::string>()});
        }
        return;
      case FieldType::vertex_list:
        if (!value.is_array() || value.empty()) {
          return checker_.problem(where, "must be a non-empty array of vertex ids");
        }
        for (std::size_t index = 0; index < value.size(); ++index) {
          const std::string item_where = where + "[" + std::to_string(index) + "]";
          if (!value[index].is_string()) {
            checker_.problem(item_where, "must be a vertex id (a string)");
          } else if (check_vertex(value[index].get<std::string>(), item_where)) {
            options.insert(options.end(), {option, value[index].get<std::string>()});
          }
        }
        return;
      case FieldType::partition: {
        if (!value.is_string()) return checker_.problem(where, "must be a partition name (a string)");
        if (!topology_) return;  // the topology's own problems are reported already
        const auto partitions = topology_->partitions();
        if (std::find(partitions.begin(), partitions.end(), value.get<std::string>()) == partitions.end()) {
          std::string list;
          for (const auto& name : partitions) list += (list.empty() ? "" : ", ") + name;
          return checker_.problem(where, "the topology has no partition '" + value.get<std::string>() +
                                             "' (it has: " + (list.empty() ? "none" : list) + ")");
        }
        options.insert(options.end(), {option, value.get<std::string>()});
        return;
      }
      case FieldType::number:
      case FieldType::positive_number: {
        const bool positive = rule.type == FieldType::positive_number;
        const double number = value.is_number() ? value.get<double>() : std::nan("");
        // NaN fails both comparisons; JSON has no infinities.
        if (!(positive ? number > 0 : number >= rule.least) || !(number <= rule.most)) {
          return checker_.problem(where, positive ? fmt::format("must be a number > 0 and at most {}", rule.most)
                                                  : fmt::format("must be a number from {} to {}", rule.least, rule.most));
        }
        options.insert(options.end(), {option, format_number(number)});
        return;
      }
      case FieldType::count: {
        // The bounds are within 2^53, so comparing as doubles is exact.
        const auto count = json_integer(value);
        if (!count || static_cast<double>(*count) < rule.least || static_cast<double>(*count) > rule.most) {
          return checker_.problem(where, fmt::format("must be an integer from {} to {}", rule.least, rule.most));
        }
        options.insert(options.end(), {option, std::to_string(*count)});
        return;
      }
      case FieldType::flag:
        if (!value.is_boolean()) return checker_.problem(where, "must be true or false");
        if (value.get<bool>()) options.push_back(option);
        return;
      case FieldType::journal: {
        if (!value.is_string() || value.get<std::string>().empty()) {
          return checker_.problem(where, "must be a file path (relative: in the state directory)");
        }
        std::filesystem::path journal = value.get<std::string>();
        if (journal.is_relative()) journal = state_dir_ / journal;
        const std::string file = journal.lexically_normal().string();
        // A second agent on a journal would be refused at its start (the file is locked).
        if (auto [other, inserted] = journal_users_.emplace(file, where); !inserted) {
          return checker_.problem(where, "journal " + file + " is " + other->second + "'s too (one journal per agent)");
        }
        options.insert(options.end(), {option, file});
        if (journals != nullptr) journals->push_back(file);
        return;
      }
    }
  }

  bool check_vertex(const std::string& id, const std::string& where) {
    if (!topology_) return false;
    const auto entity = topology_->find(id);
    if (!entity || !topology_->is_vertex(*entity)) {
      checker_.problem(where, "'" + id + "' is not a vertex of " + file_.topology_file.string());
      return false;
    }
    return true;
  }

  /// Checks across entries: unique ids, one RAN per vehicle, start vertices apart,
  /// topology agents covering every partition once, a vehicle's simulator and logical agent
  /// on one profile.
  void check_fleet() {
    std::map<std::string, std::size_t> ids;
    std::map<std::string, std::size_t> ran_vehicles;
    std::map<std::string, std::size_t> logical_vehicles;
    std::map<std::string, std::size_t> partition_owner;
    std::map<topology::EntityIndex, std::size_t> start_owner;
    std::optional<std::size_t> whole_topology_owner;  // a topology agent without a partition
    bool any_topology_agent = false;
    for (std::size_t index = 0; index < file_.agents.size(); ++index) {
      const auto& agent = file_.agents[index];
      const std::string& where = wheres_[index];
      if (auto [it, inserted] = ids.emplace(agent.id, index); !inserted) {
        checker_.problem(where + ".id", "agent id '" + agent.id + "' is used by " + wheres_[it->second] +
                                            " too (ids must be unique; set \"id\")");
      }
      if (agent.kind == AgentKind::ran_sim) {
        if (auto [it, inserted] = ran_vehicles.emplace(agent.vehicle, index); !inserted) {
          checker_.problem(where + ".vehicle", "vehicle '" + agent.vehicle + "' has a ran-sim at " +
                                                   wheres_[it->second] + " already");
        }
        check_start(index, start_owner);
      }
      if (agent.kind == AgentKind::logical) logical_vehicles.emplace(agent.vehicle, index);
      if (agent.kind == AgentKind::topology) {
        any_topology_agent = true;
        if (partitions_[index].empty()) {
          // It serves every partition: two agents would own the same entities, and vehicles
          // could be booked onto one entity through either.
          if (whole_topology_owner) {
            checker_.problem(where, "serves the whole topology, as " + wheres_[*whole_topology_owner] +
                                        " does already (give each topology agent its own \"partition\")");
          } else {
            whole_topology_owner = index;
          }
        } else if (auto [it, inserted] = partition_owner.emplace(partitions_[index], index); !inserted) {
          checker_.problem(where + ".partition", "partition '" + partitions_[index] + "' is served by " +
                                                     wheres_[it->second] + " already");
        }
      }
    }
    if (whole_topology_owner) {
      for (const auto& [partition, index] : partition_owner) {
        checker_.problem(wheres_[index] + ".partition", "partition '" + partition + "' is served by " +
                                                            wheres_[*whole_topology_owner] +
                                                            " already (it serves the whole topology)");
      }
    }
    check_profiles(ran_vehicles, logical_vehicles);
    if (topology_ && any_topology_agent && !whole_topology_owner) {
      for (const auto& partition : topology_->partitions()) {
        if (!partition_owner.contains(partition)) {
          checker_.problem("agents", "no topology agent serves partition '" + partition + "'");
        }
      }
    }
  }

  /// A vehicle's simulator drives with its profile's speeds, and its logical agent plans with
  /// them: both must name the same profile (or neither), or the vehicle runs behind or ahead
  /// of the windows reserved for it.
  void check_profiles(const std::map<std::string, std::size_t>& rans,
                      const std::map<std::string, std::size_t>& logicals) {
    for (const auto& [vehicle, ran] : rans) {
      const auto logical = logicals.find(vehicle);
      if (logical == logicals.end() || profile_names_[ran] == profile_names_[logical->second]) continue;
      const auto named = [&](std::size_t index) {
        return profile_names_[index].empty() ? std::string("no profile") : "profile '" + profile_names_[index] + "'";
      };
      checker_.problem(wheres_[logical->second] + ".profile",
                       "vehicle '" + vehicle + "' is planned with " + named(logical->second) + " but simulated with " +
                           named(ran) + " (" + wheres_[ran] + "): name the same profile in both");
    }
  }

  /// Two simulated vehicles must not start on one vertex or on conflicting ones (their
  /// footprints would overlap from the first instant).
  void check_start(std::size_t index, std::map<topology::EntityIndex, std::size_t>& start_owner) {
    if (!topology_ || starts_[index].empty()) return;
    const auto vertex = topology_->find(starts_[index]);
    if (!vertex || !topology_->is_vertex(*vertex)) return;  // reported already
    auto clash = start_owner.find(*vertex);
    for (auto other : topology_->conflicts(*vertex)) {
      if (clash == start_owner.end()) clash = start_owner.find(other);
    }
    if (clash != start_owner.end()) {
      checker_.problem(wheres_[index] + ".at", "'" + starts_[index] + "' is, or conflicts with, the start of " +
                                                   wheres_[clash->second]);
      return;
    }
    start_owner.emplace(*vertex, index);
  }

  std::filesystem::path state_dir_;
  LaunchFile file_;
  Checker checker_;
  std::optional<topology::Topology> topology_;
  struct Profile {
    std::vector<std::string> ran_options;  ///< for ran-sim
    Json logical;                          ///< for the logical agent's --vehicle file
  };
  std::map<std::string, Profile> profiles_;
  std::map<std::string, std::string> journal_users_;  ///< journal file -> the field naming it first
  // Per agent entry, parallel to file_.agents: its start vertex, its place, its partition,
  // the vehicle profile it names.
  std::vector<std::string> starts_;
  std::vector<std::string> wheres_;
  std::vector<std::string> partitions_;
  std::vector<std::string> profile_names_;
};

}  // namespace

Status prepare_state(const LaunchFile& file) {
  for (const auto& agent : file.agents) {
    std::vector<std::filesystem::path> directories;
    for (const auto& journal : agent.journals) directories.push_back(journal.parent_path());
    for (const auto& [path, content] : agent.files) directories.push_back(path.parent_path());
    for (const auto& directory : directories) {
      std::error_code error;
      std::filesystem::create_directories(directory, error);
      if (error) {
        return fail(ErrorCode::io, "agent '" + agent.id + "': cannot create directory " + directory.string() + ": " +
                                       error.message());
      }
    }
    for (const auto& [path, content] : agent.files) {
      std::ofstream out(path);
      out << content;
      if (!out.flush()) return fail(ErrorCode::io, "agent '" + agent.id + "': cannot write " + path.string());
    }
  }
  return {};
}

std::string_view kind_name(AgentKind kind) noexcept { return rules_of(kind).name; }
std::string_view subcommand(AgentKind kind) noexcept { return rules_of(kind).subcommand; }

Result<LaunchFile, LaunchProblems> parse_launch_file(std::string_view text,
                                                     const std::filesystem::path& path,
                                                     const std::filesystem::path& state_dir) {
  return LaunchFileParser(path, state_dir).parse(text);
}

Result<LaunchFile, LaunchProblems> load_launch_file(const std::filesystem::path& path,
                                                    const std::filesystem::path& state_dir) {
  auto text = read_text_file(path);
  if (!text) return unexpected(LaunchProblems{{"", std::move(text).error().message}});
  return parse_launch_file(*text, path, state_dir);
}

}  // namespace drover::launcher

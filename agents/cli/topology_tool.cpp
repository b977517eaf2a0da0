#include "agents/cli/topology_tool.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include <fmt/format.h>

#include "agents/cli/command.hpp"
#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/reader.hpp"

namespace drover::cli {

namespace {

Error bad_time(const std::string& text, bool allow_forever) {
  return Error{ErrorCode::invalid_argument,
               "'" + text + "' is not a time: give shared-clock nanoseconds (e.g. 1700000000000000000), 'now', " +
                   "'+30s' (units ns, us, ms, s, m, h)" + (allow_forever ? ", or 'forever'" : "")};
}

Error beyond_clock(const std::string& text, bool allow_forever) {
  return Error{ErrorCode::invalid_argument, fmt::format("'{}' is outside the shared clock's range [0, {}]{}", text,
                                                        kLatestTime, allow_forever ? " (use 'forever' for no end)" : "")};
}

}  // namespace

Result<TimeNs> parse_time(const std::string& text, TimeNs now, bool allow_forever) {
  if (text == "now") return now;
  if (text == "forever") {
    if (allow_forever) return kForever;
    return unexpected(bad_time(text, allow_forever));
  }
  if (!text.empty() && text[0] == '+') {
    static const std::map<std::string, double> kUnits{{"ns", 1.0},  {"us", 1e3},  {"ms", 1e6},
                                                      {"s", 1e9},   {"m", 60e9},  {"h", 3600e9}};
    const auto unit_start = text.find_first_not_of("0123456789.", 1);
    if (unit_start == std::string::npos || unit_start == 1) return unexpected(bad_time(text, allow_forever));
    const auto unit = kUnits.find(text.substr(unit_start));
    double amount = 0.0;
    const auto parsed = std::from_chars(text.data() + 1, text.data() + unit_start, amount);
    if (unit == kUnits.end() || parsed.ec != std::errc{} || parsed.ptr != text.data() + unit_start) {
      return unexpected(bad_time(text, allow_forever));
    }
    const double ns = amount * unit->second;
    if (!std::isfinite(ns)) return unexpected(bad_time(text, allow_forever));
    // In whole nanoseconds: a double near kLatestTime is off by hundreds of them.
    if (ns >= static_cast<double>(kLatestTime) ||
        std::llround(ns) > kLatestTime - std::clamp<TimeNs>(now, 0, kLatestTime)) {
      return unexpected(beyond_clock(text, allow_forever));
    }
    return now + static_cast<TimeNs>(std::llround(ns));
  }
  TimeNs absolute = 0;
  const auto parsed = std::from_chars(text.data(), text.data() + text.size(), absolute);
  if (text.empty() || parsed.ec != std::errc{} || parsed.ptr != text.data() + text.size()) {
    return unexpected(bad_time(text, allow_forever));
  }
  if (absolute < 0 || absolute > kLatestTime) return unexpected(beyond_clock(text, allow_forever));
  return absolute;
}

bool relative_time(const std::string& text) { return text == "now" || (!text.empty() && text[0] == '+'); }

Result<dds::AgentRecord> any_topology_agent(dds::Participant& participant, std::chrono::milliseconds timeout) {
  auto directory = dds::AgentDirectory::create(participant);
  if (!directory) return unexpected(directory.error());
  std::optional<dds::AgentRecord> found;
  (*directory)->wait_until(
      [&](const std::vector<dds::AgentRecord>& records) {
        for (const auto& record : records) {
          if (record.alive && record.kind == "topology") found = record;
        }
        return found.has_value();
      },
      timeout);
  if (!found) return fail(ErrorCode::unavailable, "no topology agent answered");
  return *found;
}

Result<dds::AgentRecord> find_owner(dds::Participant& participant, const std::string& entity,
                                    std::chrono::milliseconds timeout) {
  std::mutex mutex;
  std::optional<std::string> partition;
  auto descriptions = dds::Reader<msg::EntityDescription>::create(
      participant, topology_agent::kEntityTopic, [&](const msg::EntityDescription& description) {
        if (description.id() != entity) return;
        std::lock_guard lock(mutex);
        partition = description.partition();
      });
  if (!descriptions) return unexpected(descriptions.error());
  auto directory = dds::AgentDirectory::create(participant);
  if (!directory) return unexpected(directory.error());
  // The owner is known once the entity's description has come and the agent serving its
  // partition is alive; descriptions arrive independently of heartbeats, so ask again
  // after every heartbeat change and on a short period.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::optional<dds::AgentRecord> owner;
  bool any_topology = false;
  while (!owner) {
    (*directory)->wait_until(
        [&](const std::vector<dds::AgentRecord>& records) {
          std::lock_guard lock(mutex);
          any_topology = any_topology || std::any_of(records.begin(), records.end(), [](const auto& record) {
                           return record.alive && record.kind == "topology";
                         });
          if (!partition) return false;
          if (const dds::AgentRecord* live = dds::live_owner_among(records, "topology", *partition)) owner = *live;
          return owner.has_value();
        },
        std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() >= deadline) break;
  }
  if (owner) return *owner;
  if (!any_topology) return fail(ErrorCode::unavailable, "no topology agent answered");
  std::lock_guard lock(mutex);
  if (partition) {
    return fail(ErrorCode::unavailable, "entity '" + entity + "' is of partition '" + *partition +
                                            "', which no live topology agent serves");
  }
  return fail(ErrorCode::not_found, "unknown entity '" + entity + "': no topology agent describes it");
}

int exit_code_of(const Error& error) {
  switch (error.code) {
    case ErrorCode::unavailable:
    case ErrorCode::timeout:
      return kExitNoAnswer;
    case ErrorCode::not_found:
    case ErrorCode::invalid_argument:
      return kExitBadInput;
    default:
      return kExitFailure;
  }
}

}  // namespace drover::cli

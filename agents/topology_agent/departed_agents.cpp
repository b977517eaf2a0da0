// The topology agent's care of logical agents that went away (DESIGN.md "Failure
// handling"): a logical agent without a heartbeat for departed_after loses its reservations
// in this partition but for what its vehicle occupies, so that nobody waits behind a route
// no one drives; the operators are told what it keeps. A logical agent that comes back in
// time is left alone (its new life takes over itself, docs/logical-agent.md). A topology
// agent restarted from its journal owes the same to the agents it has reservations of: one
// never heard within departed_after of the start went away while this agent was down.

#include <algorithm>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "agents/topology_agent/topology_agent.hpp"
#include "drover/dds/wire_error.hpp"
#include "drover/logical_agent/names.hpp"

namespace drover::topology_agent {

namespace {
/// Real-time budget of one holdings call to another partition's owner.
constexpr std::chrono::milliseconds kHoldingsTimeout{3000};
/// How often the departures thread looks for sweeps that are due.
constexpr std::chrono::milliseconds kDeparturesPeriod{200};
}  // namespace

Status TopologyAgent::watch_logical_agents() {
  const bool sweeping = options_.departed_after.count() > 0;
  if (sweeping) {
    auto alarms = dds::Writer<msg::OperatorAlarm>::create(*participant_, logical_agent::kAlarmTopic,
                                                          logical_agent::alarm_writer_qos());
    if (!alarms) return unexpected(alarms.error());
    alarm_writer_ = std::move(*alarms);
    auto holdings = dds::ServiceClient<msg::HoldingsRequest, msg::HoldingsReply>::create(*participant_,
                                                                                         kServiceArea, "holdings");
    if (!holdings) return unexpected(holdings.error());
    holdings_client_ = std::move(*holdings);
  }
  dds::AgentDirectoryOptions watch;
  watch.on_change = [this](const dds::AgentRecord& record) { on_agent_change(record); };
  auto directory = dds::AgentDirectory::create(*participant_, std::move(watch));
  if (!directory) return unexpected(directory.error());
  directory_ = std::move(*directory);
  if (sweeping) departed_thread_ = std::thread([this] { run_departures(); });  // after directory_: it reads it
  return {};
}

void TopologyAgent::owe_heartbeats() {
  std::set<std::string> reserving;
  {
    std::lock_guard lock(mutex_);
    for (topology::EntityIndex entity = 0; entity < topology_.entity_count(); ++entity) {
      if (!timelines_.owns(entity)) continue;
      for (const auto& item : timelines_.timeline(entity).reservations) reserving.insert(item.agent);
    }
  }
  std::lock_guard lock(departed_mutex_);
  for (const auto& agent : reserving) {
    spdlog::info("logical agent '{}' has reservations here from the journal: they go in {:.1f} s unless it is heard",
                 agent, std::chrono::duration<double>(options_.departed_after).count());
    departed_[agent] = Departure{std::chrono::steady_clock::now() + options_.departed_after,
                                 "no heartbeat since this topology agent started"};
  }
}

bool TopologyAgent::heard_alive(const std::string& agent) {
  std::lock_guard lock(departed_mutex_);
  return alive_.contains(agent);
}

void TopologyAgent::on_agent_change(const dds::AgentRecord& record) {
  if (record.kind != "logical") return;
  std::lock_guard lock(departed_mutex_);
  if (record.alive) {
    alive_.insert(record.id);
    if (departed_.erase(record.id) > 0) spdlog::info("logical agent '{}' is back", record.id);
    return;
  }
  alive_.erase(record.id);
  if (options_.departed_after.count() <= 0 || departed_.contains(record.id)) return;
  spdlog::info("logical agent '{}' lost ({}): its reservations here go in {:.1f} s unless it comes back", record.id,
               record.lost_reason, std::chrono::duration<double>(options_.departed_after).count());
  departed_[record.id] = Departure{std::chrono::steady_clock::now() + options_.departed_after, record.lost_reason};
  departed_wake_.notify_all();
}

void TopologyAgent::run_departures() {
  std::unique_lock lock(departed_mutex_);
  while (!departed_wake_.wait_for(lock, kDeparturesPeriod, [this] { return departed_stop_; })) {
    const auto now = std::chrono::steady_clock::now();
    for (auto it = departed_.begin(); it != departed_.end();) {
      if (it->second.due > now) {
        ++it;
        continue;
      }
      const auto agent = it->first;
      const auto why = it->second.why;
      it = departed_.erase(it);
      lock.unlock();  // the sweep takes mutex_ and calls other agents
      sweep_departed(agent, why);
      lock.lock();
      if (departed_stop_) return;  // shutting down: the other sweeps would only delay it
      it = departed_.upper_bound(agent);  // the map may have changed meanwhile
    }
  }
}

std::optional<std::map<topology::RouteId, std::vector<std::uint32_t>>> TopologyAgent::held_abroad(
    const std::string& agent) {
  std::map<topology::RouteId, std::vector<std::uint32_t>> held;
  const auto mine = served_partitions();
  for (const auto& partition : topology_.partitions()) {
    if (std::find(mine.begin(), mine.end(), partition) != mine.end()) continue;
    if (sweep_called_off(agent)) return std::nullopt;  // each call below may take seconds
    const auto owner = directory_->live_owner_of("topology", partition);
    if (!owner) {
      spdlog::warn("what '{}' holds in partition '{}' is unknown: no live topology agent owns it", agent, partition);
      return std::nullopt;
    }
    msg::HoldingsRequest request;
    request.agent(agent);
    auto reply = holdings_client_->call(request, kHoldingsTimeout, owner->id);
    if (!reply || !dds::from_wire(reply->error())) {
      spdlog::warn("what '{}' holds in partition '{}' is unknown: '{}' did not say", agent, partition, owner->id);
      return std::nullopt;
    }
    for (const auto& step : reply->held()) held[step.route()].push_back(step.step());
  }
  return held;
}

bool TopologyAgent::sweep_called_off(const std::string& agent) {
  std::lock_guard lock(departed_mutex_);
  return departed_stop_ || alive_.contains(agent);
}

void TopologyAgent::sweep_departed(const std::string& agent, const std::string& why) {
  if (directory_) {
    if (const auto record = directory_->find(agent); record && record->alive) return;  // back just now
  }
  const auto abroad = held_abroad(agent);
  // Asking the other partitions takes up to seconds each: an agent heard again meanwhile
  // (a participant dropped under load and rediscovered) keeps its routes.
  if (sweep_called_off(agent)) return;
  std::vector<std::string> kept;
  std::size_t routes = 0;
  {
    std::lock_guard lock(mutex_);
    const auto here = timelines_.holdings_of(agent);
    if (here.routes.empty()) return;
    routes = here.routes.size();
    // The steps to keep, by route: those held anywhere. Without word from every partition,
    // every step whose origin another partition owns (it may be held there).
    std::map<topology::RouteId, std::vector<std::uint32_t>> keep = abroad.value_or(decltype(keep){});
    if (!abroad) {
      for (topology::EntityIndex entity = 0; entity < topology_.entity_count(); ++entity) {
        if (!timelines_.owns(entity)) continue;
        for (const auto& item : timelines_.timeline(entity).reservations) {
          if (item.agent == agent && !timelines_.owns(item.origin)) keep[item.route].push_back(item.step);
        }
      }
    }
    std::vector<topology::Grant> grants;
    std::vector<msg::TopologyEvent> events;
    for (const auto route : here.routes) {
      remember_withdrawn(agent, route);
      auto& steps = keep[route];
      std::sort(steps.begin(), steps.end());
      steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
      auto cancelled = timelines_.cancel_route(agent, route, steps);
      if (!cancelled) {
        spdlog::warn("route {} of departed '{}' not cancelled: {}", route, agent, cancelled.error().message);
        continue;
      }
      grants.insert(grants.end(), cancelled->begin(), cancelled->end());
      std::erase_if(prepared_, [&](const auto& entry) {
        return entry.second.agent == agent && entry.second.route == route;
      });
      msg::TopologyEvent event;
      event.kind(msg::EVENT_CANCELLED);
      event.agent(agent);
      event.route(route);
      events.push_back(std::move(event));
    }
    if (auto saved = after_change(grants, std::move(events)); !saved) {
      spdlog::error("the routes of departed '{}' were cancelled but not saved: {}", agent, saved.error().message);
      return;
    }
    for (const auto& [entity, step] : timelines_.holdings_of(agent).held) kept.push_back(topology_.id(entity));
  }
  const std::string where = fmt::format("partition(s) {}", fmt::join(served_partitions(), ", "));
  msg::OperatorAlarm alarm;
  alarm.agent(agent_id());
  alarm.vehicle(agent);
  alarm.time().ns(clock_.now());
  if (kept.empty()) {
    alarm.severity(msg::ALARM_WARNING);
    alarm.text(fmt::format("logical agent '{}' is gone ({}): its {} route(s) in {} are cancelled", agent, why, routes,
                           where));
  } else {
    // Its vehicle stands (or stood) there, driven by nobody: an operator must see to it.
    alarm.severity(msg::ALARM_ERROR);
    alarm.text(fmt::format("logical agent '{}' is gone ({}): its vehicle keeps '{}' allocated in {} until its agent "
                           "comes back or an operator releases them (droverctl release ENTITY --from {}); the rest "
                           "of its {} route(s) there is cancelled",
                           agent, why, fmt::join(kept, "', '"), where, agent, routes));
  }
  spdlog::log(kept.empty() ? spdlog::level::warn : spdlog::level::err, "alarm: {}", alarm.text());
  if (auto written = alarm_writer_->write(alarm); !written) {
    spdlog::warn("alarm not published: {}", written.error().message);
  }
}

}  // namespace drover::topology_agent

#include "agents/logical_agent/src/topology_services.hpp"

#include <algorithm>
#include <deque>
#include <set>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>

#include "drover/dds/wire_error.hpp"

namespace drover::logical_agent {

namespace {

constexpr const char* kTopologyArea = "topology";
constexpr const char* kRoutingArea = "routing";
/// Pause between retries of a call nobody answered.
constexpr std::chrono::milliseconds kRetryPause{200};
/// Pause between rounds of the cancels still due (TopologyServices::cancel_route).
constexpr std::chrono::seconds kDueCancelPause{1};
/// Bound on the cancels kept due: a partition that never gets an owner must not make the
/// list grow for ever.
constexpr std::size_t kMostCancelsDue = 4096;

bool nobody_answered(const Error& error) {
  return error.code == ErrorCode::timeout || error.code == ErrorCode::unavailable;
}

template <class Req, class Rep>
Status make_client(std::unique_ptr<dds::ServiceClient<Req, Rep>>& client, dds::Participant& participant,
                   const char* area, const char* service) {
  auto created = dds::ServiceClient<Req, Rep>::create(participant, area, service);
  if (!created) return unexpected(created.error());
  client = std::move(*created);
  return {};
}

}  // namespace

Result<std::unique_ptr<TopologyServices>> TopologyServices::create(dds::Participant& participant,
                                                                   std::shared_ptr<const topology::Topology> topology,
                                                                   std::chrono::milliseconds call_timeout,
                                                                   const std::atomic<bool>& stopping) {
  std::unique_ptr<TopologyServices> services(new TopologyServices(std::move(topology), call_timeout, stopping));
  auto directory = dds::AgentDirectory::create(participant);
  if (!directory) return unexpected(directory.error());
  services->directory_ = std::move(*directory);
  for (auto status : {make_client(services->route_client_, participant, kRoutingArea, "route"),
                      make_client(services->allocate_client_, participant, kTopologyArea, "allocate"),
                      make_client(services->release_client_, participant, kTopologyArea, "release"),
                      make_client(services->delay_client_, participant, kTopologyArea, "delay"),
                      make_client(services->cancel_client_, participant, kTopologyArea, "cancel_route"),
                      make_client(services->holdings_client_, participant, kTopologyArea, "holdings")}) {
    if (!status) return unexpected(status.error());
  }
  services->due_sender_ = std::thread([raw = services.get()] { raw->send_due_cancels(); });
  return services;
}

template <class T>
Result<T> TopologyServices::retry(const std::function<Result<T>()>& call,
                                  std::optional<std::chrono::steady_clock::time_point> give_up) const {
  for (;;) {
    auto result = call();
    if (result || !nobody_answered(result.error())) return result;
    if (stopping_ || (give_up && std::chrono::steady_clock::now() >= *give_up)) return result;
    spdlog::warn("{} (retrying)", result.error().message);
    std::this_thread::sleep_for(kRetryPause);
  }
}

Result<std::string> TopologyServices::owner_of(topology::EntityIndex entity) const {
  auto owner = owner_of_partition(topology_->partition(entity));
  if (!owner) return fail(owner.error().code, owner.error().message + " (entity '" + topology_->id(entity) + "')");
  return owner;
}

Result<std::string> TopologyServices::owner_of_partition(const std::string& partition) const {
  if (auto owner = directory_->live_owner_of("topology", partition)) return owner->id;
  return fail(ErrorCode::unavailable, "no live topology agent owns partition '" + partition + "'");
}

std::vector<std::string> TopologyServices::partitions_of(const std::string& agent_id) const {
  auto record = directory_->find(agent_id);
  return record ? record->owns : std::vector<std::string>{};
}

Result<msg::RouteReply> TopologyServices::route(msg::RouteRequest request, std::chrono::milliseconds timeout) {
  return route_client_->call(std::move(request), timeout);
}

Result<AllocateOutcome> TopologyServices::allocate(const std::string& agent, topology::EntityIndex entity,
                                                   std::chrono::milliseconds timeout) {
  auto owner = owner_of(entity);
  if (!owner) return AllocateOutcome{};  // nobody to ask now: not granted, ask again later
  msg::AllocateRequest request;
  request.agent(agent);
  request.entity(topology_->id(entity));
  request.wait(true);
  auto reply = allocate_client_->call(request, timeout, *owner);
  if (!reply) {
    if (nobody_answered(reply.error())) return AllocateOutcome{};
    return unexpected(reply.error());
  }
  if (auto status = dds::from_wire(reply->error()); !status) {
    if (nobody_answered(status.error())) return AllocateOutcome{};
    return unexpected(status.error());
  }
  return AllocateOutcome{reply->granted(), reply->queue_position()};
}

Status TopologyServices::release(const std::string& agent, topology::EntityIndex entity,
                                 std::optional<HeldStep> held) {
  const auto send = [&](const std::string& partition, bool shadows_only) {
    return retry<bool>([&]() -> Result<bool> {
      auto owner = owner_of_partition(partition);
      if (!owner) return unexpected(owner.error());
      msg::ReleaseRequest request;
      request.agent(agent);
      request.entity(topology_->id(entity));
      request.shadows_only(shadows_only);
      if (held) {
        request.route(held->route);
        request.step(held->step);
      }
      auto reply = release_client_->call(request, call_timeout_, *owner);
      if (!reply) return unexpected(reply.error());
      if (auto status = dds::from_wire(reply->error()); !status) {
        if (status.error().code == ErrorCode::not_permitted) return false;
        return unexpected(status.error());
      }
      return true;
    });
  };
  const std::string& home = topology_->partition(entity);
  if (auto done = send(home, false); !done) return unexpected(done.error());
  if (!held) return {};
  std::set<std::string> others;
  for (const auto member : topology_->conflicts(entity)) {
    if (topology_->partition(member) != home) others.insert(topology_->partition(member));
  }
  for (const auto& partition : others) {
    if (auto done = send(partition, true); !done) {
      spdlog::warn("shadows of '{}' (route {} step {}) not released in partition '{}': {}", topology_->id(entity),
                   held->route, held->step, partition, done.error().message);
    }
  }
  return {};
}

Result<std::vector<topology::Shift>> TopologyServices::delay(const std::string& agent, topology::RouteId route,
                                                              topology::EntityIndex entity, DurationNs by) {
  return retry<std::vector<topology::Shift>>([&]() -> Result<std::vector<topology::Shift>> {
    auto owner = owner_of(entity);
    if (!owner) return unexpected(owner.error());
    msg::DelayRequest request;
    request.agent(agent);
    request.route(route);
    request.entity(topology_->id(entity));
    request.by(by);
    auto reply = delay_client_->call(request, call_timeout_, *owner);
    if (!reply) return unexpected(reply.error());
    if (auto status = dds::from_wire(reply->error()); !status) return unexpected(status.error());
    std::vector<topology::Shift> shifts;
    for (const auto& shift : reply->shifts()) {
      shifts.push_back(topology::Shift{shift.agent(), shift.route(), shift.from_step(), shift.by()});
    }
    return shifts;
  });
}

Status TopologyServices::cancel_route(const std::string& agent, topology::RouteId route,
                                      const std::vector<std::uint32_t>& held_steps,
                                      const std::vector<std::string>& partitions) {
  Status outcome;
  for (const auto& partition : partitions.empty() ? topology_->partitions() : partitions) {
    DueCancel cancel{agent, route, held_steps, partition};
    auto sent = send_cancel(cancel);
    if (!sent && nobody_answered(sent.error())) {
      spdlog::warn("route {} not cancelled in partition '{}' yet: {} (sent again once its owner answers)", route,
                   partition, sent.error().message);
      keep_due(std::move(cancel));
      continue;
    }
    if (!sent && outcome) outcome = unexpected(sent.error());
  }
  return outcome;
}

Status TopologyServices::send_cancel(const DueCancel& cancel) const {
  auto owner = owner_of_partition(cancel.partition);
  if (!owner) return unexpected(owner.error());
  msg::CancelRouteRequest request;
  request.agent(cancel.agent);
  request.route(cancel.route);
  request.held_steps(cancel.held_steps);
  auto reply = cancel_client_->call(request, call_timeout_, *owner);
  if (!reply) return unexpected(reply.error());
  if (auto status = dds::from_wire(reply->error()); !status && status.error().code != ErrorCode::not_found) {
    return status;
  }
  return {};
}

void TopologyServices::keep_due(DueCancel cancel) {
  std::lock_guard lock(due_mutex_);
  add_due_locked(std::move(cancel));
  due_wake_.notify_all();
}

void TopologyServices::add_due_locked(DueCancel cancel) {
  const auto same =
      std::find_if(due_.begin(), due_.end(), [&](const DueCancel& due) { return due.same_target(cancel); });
  if (same != due_.end()) {
    *same = std::move(cancel);
    return;
  }
  if (due_.size() >= kMostCancelsDue) {
    const DueCancel& oldest = due_.front();
    spdlog::error("{} route cancels are due: route {} is given up in partition '{}' (its topology agent keeps it "
                  "until this agent is gone)",
                  due_.size(), oldest.route, oldest.partition);
    due_.pop_front();
  }
  due_.push_back(std::move(cancel));
}

std::size_t TopologyServices::cancels_due() const {
  std::lock_guard lock(due_mutex_);
  return due_.size() + in_flight_;
}

void TopologyServices::send_due_cancels() {
  std::unique_lock lock(due_mutex_);
  while (!closing_) {
    due_wake_.wait_for(lock, kDueCancelPause, [&] { return closing_.load(); });
    // Calls go out unlocked: cancel_route may add to the list meanwhile.
    std::deque<DueCancel> due = std::exchange(due_, {});
    in_flight_ = due.size();
    lock.unlock();
    std::vector<DueCancel> still_due;
    std::set<std::string> silent;  // partitions whose owner did not answer this round
    for (auto& cancel : due) {
      // Not sent while the agent stops: a call may take call_timeout, and the destructor
      // waits. Nor to an owner silent this round: each call would wait as long.
      if (stopping_ || closing_ || silent.contains(cancel.partition) ||
          !directory_->live_owner_of("topology", cancel.partition)) {
        still_due.push_back(std::move(cancel));
        continue;
      }
      if (auto sent = send_cancel(cancel); !sent && nobody_answered(sent.error())) {
        silent.insert(cancel.partition);
        still_due.push_back(std::move(cancel));
      } else if (!sent) {
        spdlog::warn("route {} not cancelled in partition '{}': {}", cancel.route, cancel.partition,
                     sent.error().message);
      } else {
        spdlog::info("route {} cancelled in partition '{}' (was due)", cancel.route, cancel.partition);
      }
    }
    lock.lock();
    in_flight_ = 0;
    // Back in front, oldest first, of those added meanwhile, which are newer: one of the
    // same route and partition among them stands instead.
    std::deque<DueCancel> added = std::exchange(due_, {});
    for (auto& cancel : still_due) {
      const bool replaced =
          std::any_of(added.begin(), added.end(), [&](const DueCancel& newer) { return newer.same_target(cancel); });
      if (!replaced) due_.push_back(std::move(cancel));
    }
    for (auto& cancel : added) add_due_locked(std::move(cancel));
  }
  for (const auto& cancel : due_) {
    spdlog::warn("route {} left reserved in partition '{}': its owner never answered the cancel (it goes once the "
                 "topology agent finds this agent gone)",
                 cancel.route, cancel.partition);
  }
}

TopologyServices::~TopologyServices() {
  {
    std::lock_guard lock(due_mutex_);
    closing_ = true;
  }
  due_wake_.notify_all();
  if (due_sender_.joinable()) due_sender_.join();
}

std::vector<std::string> TopologyServices::partitions_touched(const std::vector<topology::RouteStep>& steps) const {
  std::set<std::string> touched;
  for (const auto& step : steps) {
    touched.insert(topology_->partition(step.entity));
    for (const auto member : topology_->conflicts(step.entity)) touched.insert(topology_->partition(member));
  }
  return {touched.begin(), touched.end()};
}

Result<Holdings> TopologyServices::holdings(const std::string& agent, std::chrono::steady_clock::time_point give_up,
                                            const std::vector<std::string>& partitions) {
  Holdings out;
  for (const auto& partition : partitions.empty() ? topology_->partitions() : partitions) {
    auto reply = retry<msg::HoldingsReply>([&]() -> Result<msg::HoldingsReply> {
      auto owner = owner_of_partition(partition);
      if (!owner) return unexpected(owner.error());
      msg::HoldingsRequest request;
      request.agent(agent);
      auto answer = holdings_client_->call(request, call_timeout_, *owner);
      if (!answer) return unexpected(answer.error());
      if (auto status = dds::from_wire(answer->error()); !status) return unexpected(status.error());
      return answer;
    }, give_up);
    if (!reply && nobody_answered(reply.error()) && !stopping_) {
      out.unanswered.push_back(partition);
      continue;
    }
    if (!reply) return unexpected(reply.error());
    for (const auto& held : reply->held()) {
      const auto entity = topology_->find(held.entity());
      if (!entity) {
        spdlog::warn("'{}' holds '{}' in partition '{}', which topology '{}' does not have", agent, held.entity(),
                     partition, topology_->name());
        continue;
      }
      out.held.emplace_back(*entity, HeldStep{held.route(), held.step()});
    }
    out.routes.insert(out.routes.end(), reply->routes().begin(), reply->routes().end());
  }
  std::sort(out.routes.begin(), out.routes.end());
  out.routes.erase(std::unique(out.routes.begin(), out.routes.end()), out.routes.end());
  return out;
}

}  // namespace drover::logical_agent

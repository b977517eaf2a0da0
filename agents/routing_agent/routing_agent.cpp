#include "agents/routing_agent/routing_agent.hpp"

#include <algorithm>
#include <set>

#include <spdlog/spdlog.h>

#include "agents/routing_agent/route_wire.hpp"
#include "agents/topology_agent/wire.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/dds/wire_error.hpp"

namespace drover::routing_agent {

namespace {

using Clock = std::chrono::steady_clock;

/// Topics of the topology agents (docs/topology-agent.md).
constexpr const char* kEntityTopic = "drover/topology/entity";
constexpr const char* kTimelineTopic = "drover/topology/timeline";
constexpr const char* kTopologyArea = "topology";

std::string milliseconds_text(std::chrono::milliseconds duration) {
  return std::to_string(duration.count()) + " ms";
}

/// The part of a route that one topology agent owns.
struct PartitionShare {
  std::string partition;
  std::string owner;  // the topology agent serving it
  msg::ReservePrepareRequest request;
  std::uint64_t prepare_id = 0;
  std::vector<msg::EntityVersion> prepared_versions;
};

}  // namespace

Result<std::unique_ptr<RoutingAgent>> RoutingAgent::create(SharedClock clock, RoutingAgentOptions options) {
  if (options.max_attempts < 1) return fail(ErrorCode::invalid_argument, "max attempts must be at least 1");
  if (options.prepare_ttl <= 0) return fail(ErrorCode::invalid_argument, "prepare ttl must be positive");
  auto participant = dds::Participant::create(options.participant);
  if (!participant) return unexpected(participant.error());
  std::unique_ptr<RoutingAgent> agent(new RoutingAgent(clock, std::move(options), std::move(*participant)));
  if (auto started = agent->start(); !started) return unexpected(started.error());
  return agent;
}

RoutingAgent::RoutingAgent(SharedClock clock, RoutingAgentOptions options,
                           std::unique_ptr<dds::Participant> participant)
    : clock_(clock), options_(std::move(options)), participant_(std::move(participant)) {}

Status RoutingAgent::start() {
  auto directory = dds::AgentDirectory::create(*participant_);
  if (!directory) return unexpected(directory.error());
  directory_ = std::move(*directory);
  auto client = [this]<class Req, class Rep>(Client<Req, Rep>& out, const char* service) -> Status {
    auto created = dds::ServiceClient<Req, Rep>::create(*participant_, kTopologyArea, service);
    if (!created) return unexpected(created.error());
    out = std::move(*created);
    return {};
  };
  for (auto status : {client(prepare_client_, "reserve_prepare"), client(commit_client_, "reserve_commit"),
                      client(abort_client_, "reserve_abort"), client(cancel_client_, "cancel_route")}) {
    if (!status) return status;
  }
  dds::HeartbeatOptions beat;
  beat.kind = "routing";
  auto heartbeat = dds::HeartbeatPublisher::create(*participant_, clock_, std::move(beat));
  if (!heartbeat) return unexpected(heartbeat.error());
  heartbeat_ = std::move(*heartbeat);

  auto descriptions = dds::Reader<msg::EntityDescription>::create(
      *participant_, kEntityTopic, [this](const msg::EntityDescription& d) { on_description(d); });
  if (!descriptions) return unexpected(descriptions.error());
  description_reader_ = std::move(*descriptions);
  auto timelines = dds::Reader<msg::TimelineState>::create(
      *participant_, kTimelineTopic, [this](const msg::TimelineState& t) { on_timeline(t); });
  if (!timelines) return unexpected(timelines.error());
  timeline_reader_ = std::move(*timelines);

  auto server = dds::ServiceServer<msg::RouteRequest, msg::RouteReply>::create(
      *participant_, kServiceArea, kRouteService,
      [this](const msg::RouteRequest& request, dds::ReplyHandle<msg::RouteReply> reply) {
        on_route(request, std::move(reply));
      });
  if (!server) return unexpected(server.error());
  route_server_ = std::move(*server);
  return {};
}

RoutingAgent::~RoutingAgent() {
  // The server first (no request is being handled once it is gone), then the readers.
  route_server_.reset();
  timeline_reader_.reset();
  description_reader_.reset();
}

void RoutingAgent::on_description(const msg::EntityDescription& description) {
  {
    std::lock_guard lock(mutex_);
    if (!known_.add(description)) return;
  }
  changed_.notify_all();
}

void RoutingAgent::on_timeline(const msg::TimelineState& state) {
  {
    std::lock_guard lock(mutex_);
    if (model_) model_->apply(state);
    timelines_[state.entity()] = state;
  }
  changed_.notify_all();
}

void RoutingAgent::on_route(const msg::RouteRequest& request, dds::ReplyHandle<msg::RouteReply> reply) {
  auto served = serve(request);
  msg::RouteReply out;
  if (served) {
    out = std::move(*served);
    spdlog::info("{} route {} of '{}' for '{}': {} -> {}, {} steps, {} attempt(s)", request.real() ? "real" : "test",
                 out.route(), request.agent(), reply.requester(), request.start(),
                 request.stops().empty() ? std::string("?") : request.stops().back().vertex(), out.steps().size(),
                 out.attempts());
  } else {
    spdlog::info("route request of '{}' for '{}' failed: {}", reply.requester(), request.agent(),
                 served.error().error.message);
    out.error(dds::to_wire(served.error().error));
    out.failure(served.error().failure);
    out.blockers(served.error().blockers);
    out.route(served.error().route != 0 ? served.error().route : request.route());
  }
  if (auto sent = reply.send(std::move(out)); !sent) {
    spdlog::warn("route reply to '{}' not sent: {}", reply.requester(), sent.error().message);
  }
}

bool RoutingAgent::cancel_route_on(const std::string& agent, topology::RouteId route, const std::string& owner) {
  // A topology agent that did not answer a commit in time may be busy or restarting: the
  // cancel gets a few call timeouts, not one.
  constexpr int kAttempts = 3;
  msg::CancelRouteRequest cancel;
  cancel.agent(agent);
  cancel.route(route);
  std::string why;
  for (int attempt = 1; attempt <= kAttempts; ++attempt) {
    auto cancelled = cancel_client_->call(cancel, options_.call_timeout, owner);
    if (cancelled) {
      const auto code = cancelled->error().code();
      if (code == msg::ERROR_NONE || code == msg::ERROR_NOT_FOUND) return true;  // gone, or never committed
      why = cancelled->error().message();
      break;
    }
    why = cancelled.error().message;
  }
  spdlog::error("route {} of '{}': could not undo the commit on '{}': {}", route, agent, owner, why);
  return false;
}

Result<carp::PlanRequest, RoutingAgent::RouteError> RoutingAgent::prepare_model(std::unique_lock<std::mutex>& lock,
                                                                               const msg::RouteRequest& request) {
  std::vector<std::string> stops;
  for (const auto& stop : request.stops()) stops.push_back(stop.vertex());
  std::optional<MissingEntity> missing;
  const bool complete = changed_.wait_for(lock, options_.learn_timeout, [&] {
    missing = known_.first_missing(request.start(), stops);
    return !missing.has_value();
  });
  if (!complete) {
    const std::string waited = " (waited " + milliseconds_text(options_.learn_timeout) + " for the topology agents on domain " +
                               std::to_string(options_.participant.domain_id) + ")";
    if (missing->referenced_by.empty()) {
      return unexpected(RouteError{Error{ErrorCode::not_found, "unknown vertex '" + missing->id +
                                                                   "': no topology agent describes it" + waited},
                                   "invalid_request"});
    }
    return unexpected(RouteError{Error{ErrorCode::unavailable, "the topology around '" + request.start() +
                                                                   "' is incomplete: entity '" + missing->id +
                                                                   "' (named by '" + missing->referenced_by +
                                                                   "') is described by no topology agent" + waited},
                                 {}});
  }
  if (!model_ || model_generation_ != known_.generation()) {
    auto built = RouteModel::build(known_, options_.planner);
    if (!built) return unexpected(RouteError{built.error(), {}});
    model_ = std::move(*built);
    model_generation_ = known_.generation();
    for (const auto& [id, state] : timelines_) model_->apply(state);
    spdlog::info("model rebuilt: {} entities known", model_->topology().entity_count());
  }
  auto plan = to_plan_request(model_->topology(), request, clock_.now());
  if (!plan) return unexpected(RouteError{plan.error(), "invalid_request"});
  return std::move(*plan);
}

RoutingAgent::RouteError RoutingAgent::plan_failure(const carp::PlanError& error) {
  return RouteError{carp::to_error(error), carp::to_string(error.reason), error.blockers};
}

Result<msg::RouteReply, RoutingAgent::RouteError> RoutingAgent::serve(const msg::RouteRequest& request) {
  if (request.real() && request.agent().empty()) {
    return unexpected(RouteError{Error{ErrorCode::invalid_argument, "agent: a real route needs the agent it is for"},
                                 "invalid_request"});
  }
  std::unique_lock lock(mutex_);
  auto plan = prepare_model(lock, request);
  if (!plan) return unexpected(plan.error());
  if (request.real()) {
    lock.unlock();
    return serve_real(request, std::move(*plan));
  }
  auto route = model_->planner().plan(model_->planning_timelines(), *plan);
  if (!route) return unexpected(plan_failure(route.error()));
  msg::RouteReply reply;
  reply.route(request.route());
  reply.attempts(1);
  fill_route(model_->topology(), *route, reply);
  return reply;
}

Result<std::string> RoutingAgent::owner_of(const std::string& partition) const {
  std::string owner;
  // A routing agent that just started may know the descriptions (transient-local) before the
  // owners' first heartbeats arrive: wait for them as for the descriptions.
  const bool found = directory_->wait_until(
      [&](const std::vector<dds::AgentRecord>& agents) {
        const dds::AgentRecord* live = dds::live_owner_among(agents, "topology", partition);
        if (live) owner = live->id;
        return live != nullptr;
      },
      options_.learn_timeout);
  if (!found) {
    return fail(ErrorCode::unavailable, "no live topology agent owns partition '" + partition + "' (waited " +
                                            milliseconds_text(options_.learn_timeout) + ")");
  }
  return owner;
}

Result<msg::RouteReply, RoutingAgent::RouteError> RoutingAgent::serve_real(const msg::RouteRequest& request,
                                                                           carp::PlanRequest plan) {
  topology::RouteId route_id = request.route();
  // Without a route id from the client, each attempt takes a new one: a hold of an earlier
  // attempt whose abort was lost (a call that timed out) must not make the next attempt's
  // prepare of the same steps fail; it expires by itself.
  const auto fresh_route_id = [this] {
    std::lock_guard lock(mutex_);
    topology::RouteId id = 0;
    while (id == 0) id = route_ids_();
    return id;
  };
  auto abort_all = [this](std::vector<PartitionShare>& shares) {
    for (auto& share : shares) {
      if (share.prepare_id == 0) continue;
      msg::ReserveAbortRequest abort;
      abort.prepare_id(share.prepare_id);
      auto aborted = abort_client_->call(abort, options_.call_timeout, share.owner);
      if (!aborted || aborted->error().code() != msg::ERROR_NONE) {
        spdlog::warn("abort of prepare {} on '{}' failed (it expires by itself): {}", share.prepare_id, share.owner,
                     aborted ? aborted->error().message() : aborted.error().message);
      }
      share.prepare_id = 0;
    }
  };

  Error last_conflict{ErrorCode::conflict, "no attempt made"};
  for (int attempt = 1; attempt <= options_.max_attempts; ++attempt) {
    if (request.route() == 0) route_id = fresh_route_id();
    // Plan on the replica and split the reservations by owning partition.
    std::vector<PartitionShare> shares;
    std::map<topology::EntityIndex, std::uint64_t> planned_versions;
    std::optional<carp::Route> route;
    msg::RouteReply reply;
    {
      std::unique_lock lock(mutex_);
      if (attempt > 1) {
        // The replica may have been rebuilt meanwhile; indices are re-derived.
        msg::RouteRequest again = request;
        auto replanned = prepare_model(lock, again);
        if (!replanned) return unexpected(replanned.error());
        plan = std::move(*replanned);
      }
      auto planned = model_->planner().plan(model_->planning_timelines(), plan);
      if (!planned) {
        return unexpected(plan_failure(planned.error()));
      }
      route = std::move(*planned);
      const auto& topology = model_->topology();
      const auto items = model_->timelines().expand(plan.agent, route_id, route->steps);
      std::map<std::string, std::size_t> share_of;
      std::set<topology::EntityIndex> touched;
      for (const auto& item : items) {
        const std::string& partition = model_->partition(item.entity);
        auto [it, inserted] = share_of.try_emplace(partition, shares.size());
        if (inserted) {
          shares.emplace_back();
          shares.back().partition = partition;
          shares.back().request.agent(plan.agent);
          shares.back().request.route(route_id);
        }
        auto& share = shares[it->second];
        share.request.items().push_back(topology_agent::to_wire(topology, item));
        if (touched.insert(item.entity).second) {
          msg::EntityVersion version;
          version.entity(topology.id(item.entity));
          version.version(model_->timelines().version(item.entity));
          planned_versions[item.entity] = version.version();
          share.request.expected().push_back(std::move(version));
        }
      }
      fill_route(topology, *route, reply);
    }
    for (auto& share : shares) {
      auto owner = owner_of(share.partition);
      if (!owner) return unexpected(RouteError{owner.error(), {}});
      share.owner = std::move(*owner);
    }

    // Prepare everywhere, against the versions planned on.
    const TimeNs expires_at = clock_.now() + options_.prepare_ttl;
    std::optional<Error> failed;
    bool conflict = false;
    for (auto& share : shares) {
      share.request.expires_at(expires_at);
      auto prepared = prepare_client_->call(share.request, options_.call_timeout, share.owner);
      if (!prepared) {
        failed = Error{prepared.error().code, "prepare on topology agent '" + share.owner + "': " + prepared.error().message};
        break;
      }
      if (auto status = dds::from_wire(prepared->error()); !status) {
        conflict = status.error().code == ErrorCode::conflict;
        failed = Error{status.error().code, "prepare on topology agent '" + share.owner + "': " + status.error().message};
        break;
      }
      share.prepare_id = prepared->prepare_id();
      share.prepared_versions = prepared->versions();
    }
    if (failed) {
      abort_all(shares);
      if (!conflict) return unexpected(RouteError{*failed, {}});
      spdlog::info("route {} of '{}', attempt {}: {}; re-planning", route_id, plan.agent, attempt, failed->message);
      last_conflict = *failed;
      wait_for_replica_change(planned_versions);
      continue;
    }

    if (options_.hold_after_prepare) {
      spdlog::warn("hold-after-prepare: route {} of '{}' prepared on {} topology agent(s); not committing "
                   "(test hook), waiting for shutdown",
                   route_id, plan.agent, shares.size());
      dds::wait_for_shutdown();
      abort_all(shares);
      return unexpected(RouteError{Error{ErrorCode::unavailable, "routing agent '" + agent_id() + "' shut down"}, {}});
    }

    // Commit everywhere. A commit that fails (the hold expired) undoes the others. One whose
    // reply never came, or that failed for another reason than an expired hold (its journal
    // could not be saved), may have been applied: it is undone too.
    std::optional<Error> commit_failed;
    std::vector<PartitionShare*> to_undo;
    for (auto& share : shares) {
      msg::ReserveCommitRequest commit;
      commit.prepare_id(share.prepare_id);
      auto done = commit_client_->call(commit, options_.call_timeout, share.owner);
      Status status = done ? dds::from_wire(done->error()) : Status(unexpected(std::move(done).error()));
      if (!status) {
        commit_failed = Error{status.error().code, "commit on topology agent '" + share.owner + "': " + status.error().message};
        if (!done || status.error().code != ErrorCode::not_found) to_undo.push_back(&share);
        break;
      }
      share.prepare_id = 0;
      to_undo.push_back(&share);
    }
    if (commit_failed) {
      abort_all(shares);
      bool undone = true;
      for (auto* share : to_undo) undone = cancel_route_on(plan.agent, route_id, share->owner) && undone;
      if (!undone) {
        // Part of the route may stay reserved under this id: the client is told a topology
        // agent did not answer, so that it cancels the id in every partition and asks again
        // under another (a retry under this id would leave those parts where its cancels,
        // sent where the new route runs, never reach).
        RouteError error{Error{ErrorCode::unavailable, commit_failed->message + "; the commit could not be undone "
                                                           "everywhere (route " + std::to_string(route_id) + ")"},
                         {}};
        error.route = route_id;
        return unexpected(std::move(error));
      }
      if (commit_failed->code != ErrorCode::not_found) return unexpected(RouteError{*commit_failed, {}});
      last_conflict = Error{ErrorCode::conflict, commit_failed->message + " (the hold expired)"};
      continue;
    }

    // The next plan must see this route: wait (bounded) until the replica shows it.
    std::vector<msg::EntityVersion> versions;
    for (const auto& share : shares) {
      versions.insert(versions.end(), share.prepared_versions.begin(), share.prepared_versions.end());
    }
    wait_for_replica_versions(versions);
    reply.route(route_id);
    reply.attempts(static_cast<std::uint32_t>(attempt));
    return reply;
  }
  return unexpected(RouteError{Error{ErrorCode::conflict, "no consistent reservation after " +
                                                              std::to_string(options_.max_attempts) +
                                                              " attempts (other routes kept taking the windows); last: " +
                                                              last_conflict.message},
                               "conflict"});
}

void RoutingAgent::wait_for_replica_change(const std::map<topology::EntityIndex, std::uint64_t>& versions) {
  std::unique_lock lock(mutex_);
  const auto generation = model_generation_;
  changed_.wait_for(lock, options_.replica_wait, [&] {
    if (!model_ || model_generation_ != generation) return true;
    return std::any_of(versions.begin(), versions.end(), [&](const auto& entry) {
      return model_->timelines().version(entry.first) != entry.second;
    });
  });
}

void RoutingAgent::wait_for_replica_versions(const std::vector<msg::EntityVersion>& versions) {
  std::unique_lock lock(mutex_);
  // Committing bumps each version once more than the prepare reply said.
  changed_.wait_for(lock, options_.replica_wait, [&] {
    return std::all_of(versions.begin(), versions.end(), [&](const msg::EntityVersion& version) {
      auto found = timelines_.find(version.entity());
      return found != timelines_.end() && found->second.version() > version.version();
    });
  });
}

}  // namespace drover::routing_agent

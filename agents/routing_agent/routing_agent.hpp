#pragma once
// The routing agent (docs/routing-agent.md): serves the route service
// drover/routing/route/{request,reply} (idl/routing.idl). It starts knowing nothing: it
// learns the entity descriptions the topology agents publish, keeps a versioned replica of
// their timelines, plans with CARP on it, and commits a real route through the owning
// topology agents with prepare / commit against the versions it planned on (re-planning on
// a version conflict). Several routing agents may serve at once: the topology agents'
// version checks keep them from ever double-booking.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "agents/routing_agent/known_entities.hpp"
#include "agents/routing_agent/route_model.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/reader.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/service_server.hpp"
#include "routing.h"
#include "topology.h"

namespace drover::routing_agent {

/// The route service: drover/routing/route/{request,reply}.
inline constexpr const char* kServiceArea = "routing";
inline constexpr const char* kRouteService = "route";

struct RoutingAgentOptions {
  /// DDS domain and participant settings; participant.agent_id is the agent's id.
  dds::ParticipantOptions participant;
  carp::PlannerOptions planner;
  /// How long a request waits for the descriptions it needs (its vertices and their
  /// component) before it is answered not_found / unavailable.
  std::chrono::milliseconds learn_timeout{3000};
  /// How long a prepared hold lives on the topology agents (shared-clock ns): the bound
  /// on how long a routing agent that died between prepare and commit blocks others.
  DurationNs prepare_ttl = 5 * kNsPerSecond;
  /// Plan + prepare rounds before a real route gives up with ERROR_CONFLICT.
  int max_attempts = 5;
  /// Timeout of each call to a topology agent.
  std::chrono::milliseconds call_timeout{3000};
  /// After a version conflict, how long to wait for the replica to show the change.
  std::chrono::milliseconds replica_wait{1000};
  /// TEST HOOK (docs/routing-agent.md): after the first successful prepare of a real route,
  /// log "hold-after-prepare: ..." and wait for shutdown instead of committing, so that a
  /// test can kill the agent between prepare and commit.
  bool hold_after_prepare = false;
};

/// Serves from the moment create() returns until it is destroyed. Requests are handled one
/// at a time, in arrival order.
class RoutingAgent {
 public:
  /// \return the agent, or the DDS layer's errors (invalid_argument for a bad agent id).
  static Result<std::unique_ptr<RoutingAgent>> create(SharedClock clock, RoutingAgentOptions options);
  ~RoutingAgent();
  RoutingAgent(const RoutingAgent&) = delete;
  RoutingAgent& operator=(const RoutingAgent&) = delete;

  const std::string& agent_id() const noexcept { return participant_->agent_id(); }

 private:
  /// A failed request: the error sent back and, for planning failures, the carp reason.
  struct RouteError {
    RouteError(Error e, std::string f, std::vector<std::string> b = {})
        : error(std::move(e)), failure(std::move(f)), blockers(std::move(b)) {}
    Error error;
    std::string failure;
    std::vector<std::string> blockers;  ///< carp::PlanError::blockers
    /// The route id the reply names: the request's, or, when a commit's outcome stayed
    /// unknown, the id its reservations may be under (so that the client can cancel them).
    topology::RouteId route = 0;
  };
  static RouteError plan_failure(const carp::PlanError& error);
  template <class Req, class Rep>
  using Client = std::unique_ptr<dds::ServiceClient<Req, Rep>>;

  RoutingAgent(SharedClock clock, RoutingAgentOptions options, std::unique_ptr<dds::Participant> participant);
  Status start();

  void on_description(const msg::EntityDescription& description);
  void on_timeline(const msg::TimelineState& state);
  void on_route(const msg::RouteRequest& request, dds::ReplyHandle<msg::RouteReply> reply);
  Result<msg::RouteReply, RouteError> serve(const msg::RouteRequest& request);

  /// Waits until the request's vertices and their component are described, then makes the
  /// model current. Requires lock held on mutex_. \return the plan request on the model.
  Result<carp::PlanRequest, RouteError> prepare_model(std::unique_lock<std::mutex>& lock,
                                                      const msg::RouteRequest& request);
  Result<msg::RouteReply, RouteError> serve_real(const msg::RouteRequest& request, carp::PlanRequest plan);
  /// Cancels `agent`'s route `route` on topology agent `owner`, held or committed, asking
  /// again (a few times) while nobody answers. \return whether it is gone there (or was
  /// never there); false, logged, when it could not be made sure of.
  bool cancel_route_on(const std::string& agent, topology::RouteId route, const std::string& owner);

  /// The live topology agent that owns `partition`, from the heartbeats.
  Result<std::string> owner_of(const std::string& partition) const;
  /// Waits until some entity's replica version differs from `versions` (by model index).
  void wait_for_replica_change(const std::map<topology::EntityIndex, std::uint64_t>& versions);
  /// Waits until each entity's replica version is past `versions` (by id).
  void wait_for_replica_versions(const std::vector<msg::EntityVersion>& versions);

  const SharedClock clock_;
  const RoutingAgentOptions options_;

  // DDS entities: the participant is declared first so that it is destroyed last.
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::AgentDirectory> directory_;
  Client<msg::ReservePrepareRequest, msg::ReservePrepareReply> prepare_client_;
  Client<msg::ReserveCommitRequest, msg::StatusReply> commit_client_;
  Client<msg::ReserveAbortRequest, msg::StatusReply> abort_client_;
  Client<msg::CancelRouteRequest, msg::StatusReply> cancel_client_;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;  // a description or a timeline arrived
  KnownEntities known_;
  std::map<std::string, msg::TimelineState> timelines_;  // the last one of each entity
  std::unique_ptr<RouteModel> model_;
  std::uint64_t model_generation_ = 0;
  std::mt19937_64 route_ids_{std::random_device{}()};

  // Readers and the server last: destroyed first, so no callback runs while the rest goes.
  std::unique_ptr<dds::Reader<msg::EntityDescription>> description_reader_;
  std::unique_ptr<dds::Reader<msg::TimelineState>> timeline_reader_;
  std::unique_ptr<dds::ServiceServer<msg::RouteRequest, msg::RouteReply>> route_server_;
};

}  // namespace drover::routing_agent

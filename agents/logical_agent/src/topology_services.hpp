#pragma once
// The logical agent's calls to the topology agents and the routing agents: every call goes
// to the agent that owns the entity (from the entity's partition and the heartbeats), and
// calls that failed because nobody answered are retried (an agent restarting), so that a
// restart of a topology or routing agent loses nothing.

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_client.hpp"
#include "agents/logical_agent/src/footprint_monitor.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"
#include "routing.h"
#include "topology.h"

namespace drover::logical_agent {

struct AllocateOutcome {
  bool granted = false;
  std::size_t queue_position = 0;
};

/// What an agent has at the topology agents (TopologyServices::holdings).
struct Holdings {
  std::vector<std::pair<topology::EntityIndex, HeldStep>> held;  ///< the entities it holds
  std::vector<topology::RouteId> routes;  ///< routes it has reservations of, ascending, each once
  std::vector<std::string> unanswered;    ///< partitions whose owner did not answer in time
};

/// Thread-safe. Must be destroyed before its Participant.
class TopologyServices {
 public:
  /// \param stopping  read before every retry: once true, calls give up with unavailable.
  static Result<std::unique_ptr<TopologyServices>> create(dds::Participant& participant,
                                                          std::shared_ptr<const topology::Topology> topology,
                                                          std::chrono::milliseconds call_timeout,
                                                          const std::atomic<bool>& stopping);

  /// Plans (and with `real`, reserves) a route. \return the reply (its error says whether
  /// planning worked), or timeout / unavailable when no routing agent answered.
  Result<msg::RouteReply> route(msg::RouteRequest request, std::chrono::milliseconds timeout);

  /// Allocation of `entity` (wait = true: the owner answers when granted). A call that
  /// times out is no error: the request stays queued, the outcome says not granted.
  /// \return the outcome, or the owner's error (not_found: no reservation of ours there).
  Result<AllocateOutcome> allocate(const std::string& agent, topology::EntityIndex entity,
                                   std::chrono::milliseconds timeout);
  /// Releases `entity`, retrying while the owner does not answer. not_permitted (we do not
  /// hold it) counts as done. With `held` (the route step the allocation was), the other
  /// partitions owning members of the entity's conflict set then drop that step's shadows
  /// (a failure there is logged: the shadows go at the latest with the route).
  /// \return success, or the owner's error.
  Status release(const std::string& agent, topology::EntityIndex entity, std::optional<HeldStep> held);
  /// Delays `route` from its step on `entity` by `by`. \return the reply's shifts, or the
  /// owner's error.
  Result<std::vector<topology::Shift>> delay(const std::string& agent, topology::RouteId route,
                                             topology::EntityIndex entity, DurationNs by);
  /// Cancels `route` on every live topology agent (not_found there is fine), retrying the
  /// ones that do not answer (until `give_up`, when given). The route's `held_steps`
  /// (allocations the vehicle still stands on) stay with their shadows in every partition,
  /// to go with their release. A partition that fails does not keep the others from it.
  /// \return success, or the first error.
  Status cancel_route(const std::string& agent, topology::RouteId route, const std::vector<std::uint32_t>& held_steps,
                      std::optional<std::chrono::steady_clock::time_point> give_up = std::nullopt);

  /// What `agent` has at the owners of every partition, each asked until it answers or
  /// `give_up` has passed (then it is listed as unanswered). Entities the topology does not
  /// know are left out (with a warning).
  /// \return them, or the first other error (unavailable once stopping).
  Result<Holdings> holdings(const std::string& agent, std::chrono::steady_clock::time_point give_up);

  /// The live topology agent owning `entity`. \return its id, or unavailable.
  Result<std::string> owner_of(topology::EntityIndex entity) const;
  /// The live topology agent owning `partition`. \return its id, or unavailable.
  Result<std::string> owner_of_partition(const std::string& partition) const;
  /// The partitions the agent `agent_id` says it owns (empty when unknown).
  std::vector<std::string> partitions_of(const std::string& agent_id) const;

 private:
  template <class Req, class Rep>
  using Client = std::unique_ptr<dds::ServiceClient<Req, Rep>>;

  TopologyServices(std::shared_ptr<const topology::Topology> topology, std::chrono::milliseconds call_timeout,
                   const std::atomic<bool>& stopping)
      : topology_(std::move(topology)), call_timeout_(call_timeout), stopping_(stopping) {}
  /// Runs `call` until it returns something else than timeout/unavailable, or stopping, or
  /// `give_up` (when given) has passed.
  template <class T>
  Result<T> retry(const std::function<Result<T>()>& call,
                  std::optional<std::chrono::steady_clock::time_point> give_up = std::nullopt) const;

  std::shared_ptr<const topology::Topology> topology_;
  std::chrono::milliseconds call_timeout_;
  const std::atomic<bool>& stopping_;
  std::unique_ptr<dds::AgentDirectory> directory_;
  Client<msg::RouteRequest, msg::RouteReply> route_client_;
  Client<msg::AllocateRequest, msg::AllocateReply> allocate_client_;
  Client<msg::ReleaseRequest, msg::StatusReply> release_client_;
  Client<msg::DelayRequest, msg::DelayReply> delay_client_;
  Client<msg::CancelRouteRequest, msg::StatusReply> cancel_client_;
  Client<msg::HoldingsRequest, msg::HoldingsReply> holdings_client_;
};

}  // namespace drover::logical_agent

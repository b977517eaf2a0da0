#pragma once
// The logical agent's calls to the topology agents and the routing agents: every call goes
// to the agent that owns the entity (from the entity's partition and the heartbeats), and
// calls that failed because nobody answered are retried (an agent restarting), so that a
// restart of a topology or routing agent loses nothing.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
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
  ~TopologyServices();

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
  /// Cancels `route` at the owners of `partitions` (every partition of the topology when
  /// empty: a route whose steps are unknown); not_found there is fine. The route's
  /// `held_steps` (allocations the vehicle still stands on) stay with their shadows, to go
  /// with their release. Each owner is asked once: a partition without a live owner, or
  /// whose owner does not answer, is not waited for (a vehicle must not stand still because
  /// a topology agent it does not need is down); the cancel stays due and is sent again in
  /// the background, every second while the partition has a live owner, until one answers
  /// (a topology agent restarted from its journal still has the route). A partition that
  /// fails does not keep the others from it.
  /// \return success (a cancel left due counts), or the first error an owner answered.
  Status cancel_route(const std::string& agent, topology::RouteId route, const std::vector<std::uint32_t>& held_steps,
                      const std::vector<std::string>& partitions = {});
  /// The partitions where a route over `steps` has reservations: those of its entities and
  /// of the members of their conflict sets (the shadows), each once.
  std::vector<std::string> partitions_touched(const std::vector<topology::RouteStep>& steps) const;
  /// How many (route, partition) cancels are still due (see cancel_route).
  std::size_t cancels_due() const;

  /// What `agent` has at the owners of `partitions` (empty: every partition), each asked
  /// until it answers or `give_up` has passed (then it is listed as unanswered). Entities
  /// the topology does not know are left out (with a warning).
  /// \return them, or the first other error (unavailable once stopping).
  Result<Holdings> holdings(const std::string& agent, std::chrono::steady_clock::time_point give_up,
                            const std::vector<std::string>& partitions = {});

  /// The live topology agent owning `entity`. \return its id, or unavailable.
  Result<std::string> owner_of(topology::EntityIndex entity) const;
  /// The live topology agent owning `partition`. \return its id, or unavailable.
  Result<std::string> owner_of_partition(const std::string& partition) const;
  /// The partitions the agent `agent_id` says it owns (empty when unknown).
  std::vector<std::string> partitions_of(const std::string& agent_id) const;

 private:
  template <class Req, class Rep>
  using Client = std::unique_ptr<dds::ServiceClient<Req, Rep>>;

  /// A cancel of one route in one partition, not yet answered.
  struct DueCancel {
    std::string agent;
    topology::RouteId route = 0;
    std::vector<std::uint32_t> held_steps;
    std::string partition;
    /// Whether `other` cancels the same route in the same partition (the later one stands).
    bool same_target(const DueCancel& other) const {
      return route == other.route && partition == other.partition && agent == other.agent;
    }
  };

  TopologyServices(std::shared_ptr<const topology::Topology> topology, std::chrono::milliseconds call_timeout,
                   const std::atomic<bool>& stopping)
      : topology_(std::move(topology)), call_timeout_(call_timeout), stopping_(stopping) {}
  /// Asks the owner of `cancel.partition` once. \return success (not_found included),
  /// timeout / unavailable when nobody answered, or the owner's error.
  Status send_cancel(const DueCancel& cancel) const;
  /// Keeps `cancel` due (replacing an older one of the same route and partition).
  void keep_due(DueCancel cancel);
  /// Adds `cancel` to due_ (due_mutex_ held), replacing one of the same route and
  /// partition; past the bound the oldest is given up.
  void add_due_locked(DueCancel cancel);
  /// The background thread: sends the due cancels until the services close.
  void send_due_cancels();
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

  mutable std::mutex due_mutex_;
  std::condition_variable due_wake_;
  std::deque<DueCancel> due_;  ///< oldest first
  std::size_t in_flight_ = 0;  ///< taken from due_ by the round under way (cancels_due counts them)
  std::atomic<bool> closing_{false};  ///< set once, by the destructor
  std::thread due_sender_;  ///< runs send_due_cancels; joined before the clients go
};

}  // namespace drover::logical_agent

#pragma once
// The topology agent (docs/topology-agent.md): owns the entities of one partition of a
// topology (or all of them), publishes their static descriptions and timelines, and serves
// the reservation, allocation, lock, delay and cancel services over DDS. One TimelineSet
// holds the state; every service handler runs under one mutex, so each request is applied
// whole before the next one, and every changed timeline is republished before the reply.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <deque>
#include <map>
#include <set>
#include <optional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "agents/topology_agent/journal.hpp"
#include "drover/dds/agent_directory.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/writer.hpp"
#include "drover/topology/model.hpp"
#include "drover/topology/timeline.hpp"
#include "topology.h"

namespace drover::dds {
DROVER_DDS_MESSAGE(TopologyEvent);
}  // namespace drover::dds

namespace drover::topology_agent {

/// Topics and services (area "topology") of the topology agents.
inline constexpr const char* kEntityTopic = "drover/topology/entity";
inline constexpr const char* kTimelineTopic = "drover/topology/timeline";
inline constexpr const char* kNoticeTopic = "drover/topology/notices";
/// What the agents changed (TopologyEvent), for traces; events QoS.
inline constexpr const char* kEventTopic = "drover/topology/events";
inline constexpr const char* kServiceArea = "topology";

struct TopologyAgentOptions {
  /// The partition served; empty: every entity of the topology.
  std::string partition;
  /// DDS domain and participant settings; participant.agent_id is the agent's id.
  dds::ParticipantOptions participant;
  /// The SQLite journal (docs/topology-agent.md "Persistence"); empty: none, the state
  /// lives in memory only.
  std::filesystem::path journal_file;
  /// How often prepared holds past their expiry are dropped.
  std::chrono::milliseconds expiry_period{100};
  /// A logical agent without a heartbeat this long (real time) loses its reservations in
  /// this partition but for what its vehicle occupies, and the operators are told what it
  /// keeps (DESIGN.md "Failure handling"; docs/topology-agent.md "Departed logical
  /// agents"). 0: never.
  std::chrono::milliseconds departed_after{10000};
  /// TEST HOOK: commits are applied but never answered (a reply lost on the way), so that
  /// tests can check what a routing agent does with a commit of unknown outcome.
  bool drop_commit_replies = false;
};

/// Thread-safe; serves from the moment create() returns until it is destroyed.
class TopologyAgent {
 public:
  /// Starts serving `topology` (the part of it options.partition names).
  /// With a journal file, the timelines are restored from it first.
  /// \return the agent, or invalid_argument (a partition that owns no entity of the
  ///         topology, a bad agent id, a journal that breaks the invariants), the
  ///         journal's errors (io, parse, conflict, unavailable, naming the file) or the
  ///         DDS layer's errors.
  static Result<std::unique_ptr<TopologyAgent>> create(topology::Topology topology, SharedClock clock,
                                                       TopologyAgentOptions options);
  /// Stops the expiry sweep, answers queued allocation requests with `unavailable` and
  /// deletes the DDS entities.
  ~TopologyAgent();
  TopologyAgent(const TopologyAgent&) = delete;
  TopologyAgent& operator=(const TopologyAgent&) = delete;

  const std::string& agent_id() const noexcept { return participant_->agent_id(); }
  /// The partitions this agent serves (what its heartbeat says it owns).
  std::vector<std::string> served_partitions() const;
  /// Number of entities it owns.
  std::size_t owned_count() const noexcept { return owned_count_; }

 private:
  template <class Req, class Rep>
  using Server = std::unique_ptr<dds::ServiceServer<Req, Rep>>;
  using StatusHandle = dds::ReplyHandle<msg::StatusReply>;
  using AllocateHandle = dds::ReplyHandle<msg::AllocateReply>;

  TopologyAgent(topology::Topology topology, SharedClock clock, TopologyAgentOptions options,
                std::size_t owned_count, topology::TimelineSet timelines,
                std::optional<Journal> journal, std::unique_ptr<dds::Participant> participant);
  Status start();

  /// The owned entity named `id`, or not_found (unknown, or of another partition).
  Result<topology::EntityIndex> owned_entity(const std::string& id) const;
  /// The entity `id` of the topology, owned here or not. \return it, or not_found.
  Result<topology::EntityIndex> known_entity(const std::string& id) const;

  void on_prepare(const msg::ReservePrepareRequest& request, dds::ReplyHandle<msg::ReservePrepareReply> reply);
  void on_commit(const msg::ReserveCommitRequest& request, StatusHandle reply);
  void on_abort(const msg::ReserveAbortRequest& request, StatusHandle reply);
  void on_allocate(const msg::AllocateRequest& request, AllocateHandle reply);
  void on_release(const msg::ReleaseRequest& request, StatusHandle reply);
  void on_lock(const msg::LockRequest& request, dds::ReplyHandle<msg::LockReply> reply);
  void on_unlock(const msg::UnlockRequest& request, StatusHandle reply);
  void on_delay(const msg::DelayRequest& request, dds::ReplyHandle<msg::DelayReply> reply);
  void on_cancel_route(const msg::CancelRouteRequest& request, StatusHandle reply);
  void on_holdings(const msg::HoldingsRequest& request, dds::ReplyHandle<msg::HoldingsReply> reply);
  void run_expiry();

  // ---- logical agents that went away (departed_agents.cpp) ----
  /// Starts watching the logical agents' heartbeats: which are alive (heard_alive), and,
  /// with departed_after > 0, the sweeps of those that went away.
  Status watch_logical_agents();
  /// Whether logical agent `agent`'s heartbeat is heard here now (false until the first
  /// heartbeats came in after the start). Takes departed_mutex_: never call with mutex_ held.
  bool heard_alive(const std::string& agent);
  /// Makes a sweep due departed_after from now for every agent with reservations here (a
  /// journal's), called off by its first heartbeat (on_agent_change).
  /// \pre called before any request is served and before the directory exists (its first
  ///      word of an agent may come at once)
  void owe_heartbeats();
  /// From the directory's thread: a logical agent died (its sweep is due departed_after
  /// later) or came back (nothing is due).
  void on_agent_change(const dds::AgentRecord& record);
  /// The departures thread: sweeps each departed agent once its time is due, unless it came
  /// back meanwhile.
  void run_departures();
  /// Cancels every route `agent` has in this partition but for the steps it holds in any
  /// partition (its vehicle may stand on them or drive into them), and raises an operator
  /// alarm naming what it keeps allocated here. Takes mutex_ itself.
  void sweep_departed(const std::string& agent, const std::string& why);
  /// Whether the sweep of `agent` is to stop: it is heard again, or the agent shuts down.
  /// Takes departed_mutex_.
  bool sweep_called_off(const std::string& agent);
  /// The steps `agent` holds in the other partitions, by route, asked of their owners (no
  /// lock held: they may be asking this agent at the same time). nullopt when an owner did
  /// not answer, or when the sweep was called off meanwhile (sweep_called_off).
  std::optional<std::map<topology::RouteId, std::vector<std::uint32_t>>> held_abroad(const std::string& agent);

  // The members below run with mutex_ held.
  /// Saves every owned timeline whose version differs from the one last published to the
  /// journal, then republishes them, answers queued allocation requests that were granted
  /// or withdrawn, and sends a NOTICE_ALLOCATION_GRANTED for every grant the timelines
  /// made (`grants`). \return the journal's error when the save failed: then nothing is published,
  /// the operation must not be acknowledged, and the agent shuts down (its memory is
  /// ahead of its journal; a restart continues from the journal).
  /// After the save, `events` (what the operation did) are published, then an
  /// EVENT_ALLOCATED for every grant; notify_grants false leaves out the grants' notices
  /// (the requester learns it from the reply).
  /// Whether a lock on `entity` or a member of its conflict set is in force now. Requires
  /// mutex_ held.
  bool locked_now(topology::EntityIndex entity) const;
  /// Whether `agent`'s first committed real reservation on `entity` is step 0 of its route
  /// (where the vehicle stands when it planned). Requires mutex_ held.
  bool first_step_of_route(topology::EntityIndex entity, const std::string& agent) const;
  /// Remembers that `agent` gave up `route` (the last kWithdrawnKept such routes): later
  /// prepares of it are refused. Requires mutex_ held.
  void remember_withdrawn(const std::string& agent, topology::RouteId route);
  Status after_change(const std::vector<topology::Grant>& grants, std::vector<msg::TopologyEvent> events = {},
                      bool notify_grants = true);
  void notify(msg::ReservationNotice notice);
  void notify_hit(const topology::Reservation& hit, const std::string& lock_id);
  /// Publishes `event` on kEventTopic with its time, source and sequence number filled in.
  void record(msg::TopologyEvent event);
  /// An event of `kind` about `item` (agent, route, step, entity, window), not yet published.
  msg::TopologyEvent make_event(msg::TopologyEventKind kind, const topology::Reservation& item) const;
  /// The reservation of (agent, route) on the owned entities from which a delay moved it:
  /// its real reservation of the lowest step >= from_step here, else its shadow of that
  /// step; nullopt when none is left here.
  std::optional<topology::Reservation> first_moved(const topology::AgentId& agent, topology::RouteId route,
                                                   std::uint32_t from_step) const;

  const topology::Topology topology_;
  const SharedClock clock_;
  const TopologyAgentOptions options_;
  const std::size_t owned_count_;

  // DDS entities: the participant is declared first so that it is destroyed last.
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::Writer<msg::EntityDescription>> description_writer_;
  std::unique_ptr<dds::Writer<msg::TimelineState>> timeline_writer_;
  std::unique_ptr<dds::Writer<msg::ReservationNotice>> notice_writer_;
  std::unique_ptr<dds::Writer<msg::TopologyEvent>> event_writer_;
  std::uint64_t event_serial_ = 0;
  std::unique_ptr<dds::HeartbeatPublisher> heartbeat_;

  mutable std::mutex mutex_;
  topology::TimelineSet timelines_;
  std::optional<Journal> journal_;
  std::vector<std::uint64_t> published_versions_;  // per entity; last version published
  struct PreparedRoute {
    std::string agent;
    topology::RouteId route = 0;
    std::vector<topology::Reservation> real_items;  // its real reservations, as prepared
  };
  std::map<topology::PrepareId, PreparedRoute> prepared_;  // to tell owners of expired holds
  /// Routes their own agent cancelled (remember_withdrawn), oldest first in withdrawn_order_.
  static constexpr std::size_t kWithdrawnKept = 65536;
  std::set<std::pair<std::string, topology::RouteId>> withdrawn_;
  std::deque<std::pair<std::string, topology::RouteId>> withdrawn_order_;
  std::vector<StatusHandle> unanswered_commits_;            // drop_commit_replies
  /// Allocation requests with wait = true that are queued, the latest per agent and entity:
  /// answered when granted.
  std::map<std::pair<std::string, topology::EntityIndex>, AllocateHandle> waiting_replies_;

  /// A journal save failed: nothing is saved or published any more (after_change).
  bool journal_failed_ = false;
  std::condition_variable expiry_wake_;
  bool stopping_ = false;
  std::thread expiry_thread_;

  // Departed logical agents, under departed_mutex_ (never taken with mutex_ held).
  std::unique_ptr<dds::AgentDirectory> directory_;
  std::unique_ptr<dds::ServiceClient<msg::HoldingsRequest, msg::HoldingsReply>> holdings_client_;
  std::unique_ptr<dds::Writer<msg::OperatorAlarm>> alarm_writer_;
  std::mutex departed_mutex_;
  std::condition_variable departed_wake_;
  bool departed_stop_ = false;
  struct Departure {
    std::chrono::steady_clock::time_point due;
    std::string why;
  };
  std::map<std::string, Departure> departed_;  ///< logical agent id -> its sweep
  std::set<std::string> alive_;                ///< logical agents whose heartbeat is heard
  std::thread departed_thread_;

  // Servers last: destroyed first, so no handler runs while the rest goes away.
  Server<msg::ReservePrepareRequest, msg::ReservePrepareReply> prepare_server_;
  Server<msg::ReserveCommitRequest, msg::StatusReply> commit_server_;
  Server<msg::ReserveAbortRequest, msg::StatusReply> abort_server_;
  Server<msg::AllocateRequest, msg::AllocateReply> allocate_server_;
  Server<msg::ReleaseRequest, msg::StatusReply> release_server_;
  Server<msg::LockRequest, msg::LockReply> lock_server_;
  Server<msg::UnlockRequest, msg::StatusReply> unlock_server_;
  Server<msg::DelayRequest, msg::DelayReply> delay_server_;
  Server<msg::CancelRouteRequest, msg::StatusReply> cancel_server_;
  Server<msg::HoldingsRequest, msg::HoldingsReply> holdings_server_;
};

}  // namespace drover::topology_agent

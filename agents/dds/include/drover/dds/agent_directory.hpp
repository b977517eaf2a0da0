#pragma once
// The live agents of a domain, learnt from their heartbeats. An agent is dead once its
// heartbeat misses the deadline, or once its participant is dropped (lease expired: killed
// or cut off) or removed (closed). Writer liveliness is not used: Fast DDS 2.9.1 keeps dead
// writers alive while their participant has a live one (docs/dds.md).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/detail/reader_core.hpp"
#include "drover/dds/detail/serial_executor.hpp"
#include "drover/dds/heartbeat_publisher.hpp"
#include "drover/dds/participant.hpp"

namespace drover::dds {

struct AgentRecord {
  std::string id;
  std::string kind;
  std::string version;
  std::vector<std::string> owns;
  TimeNs sim_time = 0;  ///< shared-clock time of its last heartbeat
  bool alive = false;
  /// Why it is considered dead: "heartbeat deadline missed", "participant dropped" or
  /// "participant removed"; empty while alive.
  std::string lost_reason;

  friend bool operator==(const AgentRecord&, const AgentRecord&) = default;
};

/// The live agent of `kind` among `records` that owns `partition` (the first by order of
/// `records`, which the directory sorts by id), or nullptr. Where each partition is found:
/// every service call to a partition goes to the agent this names.
const AgentRecord* live_owner_among(const std::vector<AgentRecord>& records, std::string_view kind,
                                    std::string_view partition);

struct AgentDirectoryOptions {
  /// Requested heartbeat deadline; must not be shorter than the agents' (see
  /// kHeartbeatDeadline).
  std::chrono::milliseconds deadline = kHeartbeatDeadline;
  /// Called with the new record whenever an agent appears, changes, dies or comes back;
  /// on the directory's own thread, in order.
  std::function<void(const AgentRecord&)> on_change;
};

/// Thread-safe. Must be destroyed before its Participant, not from inside on_change.
class AgentDirectory {
 public:
  /// \return the directory, or the reader's errors.
  static Result<std::unique_ptr<AgentDirectory>> create(Participant& participant,
                                                        AgentDirectoryOptions options = {});
  ~AgentDirectory();

  /// Every agent seen so far, alive or dead, sorted by id.
  std::vector<AgentRecord> agents() const;
  /// The agents alive now, sorted by id.
  std::vector<AgentRecord> live_agents() const;
  std::optional<AgentRecord> find(const std::string& id) const;
  /// The live agent of `kind` that owns `partition` now (see live_owner_among), if any.
  std::optional<AgentRecord> live_owner_of(std::string_view kind, std::string_view partition) const;

  /// Waits until `predicate` holds for the records (as agents() returns them), evaluated
  /// after every change. \return whether it holds.
  bool wait_until(const std::function<bool(const std::vector<AgentRecord>&)>& predicate,
                  std::chrono::milliseconds timeout) const;
  /// Waits until agent `id` is known and alive (alive = true) or known and dead (false).
  bool wait_for_agent(const std::string& id, bool alive, std::chrono::milliseconds timeout) const;

 private:
  explicit AgentDirectory(Participant& participant, AgentDirectoryOptions options);
  void on_heartbeat(const msg::Heartbeat& beat, const eprosima::fastdds::dds::SampleInfo& info);
  void on_deadline_missed(const eprosima::fastrtps::rtps::InstanceHandle_t& instance);
  void on_participant_event(const ParticipantEvent& event);
  /// Marks `id` dead for `reason` unless it is already; requires mutex_ held.
  void mark_dead_locked(const std::string& id, const std::string& reason);
  void publish_change_locked(const AgentRecord& record);
  std::vector<AgentRecord> agents_locked() const;

  struct Entry {
    AgentRecord record;
    eprosima::fastrtps::rtps::GuidPrefix_t participant;  ///< where its heartbeat comes from
  };

  Participant& participant_;
  AgentDirectoryOptions options_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::map<std::string, Entry> entries_;
  std::map<eprosima::fastrtps::rtps::InstanceHandle_t, std::string> id_by_instance_;
  /// Participants reported removed or dropped: their late heartbeats are ignored.
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> gone_participants_;
  detail::SerialExecutor notifier_;
  std::uint64_t events_token_ = 0;
  std::unique_ptr<detail::ReaderCore> reader_;
};

}  // namespace drover::dds

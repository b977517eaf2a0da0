#include "drover/dds/agent_directory.hpp"

#include <algorithm>
#include <utility>

#include <spdlog/spdlog.h>

#include "drover/dds/message_types.hpp"

namespace drover::dds {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::InstanceHandle_t;

const AgentRecord* live_owner_among(const std::vector<AgentRecord>& records, std::string_view kind,
                                    std::string_view partition) {
  const auto owner = std::find_if(records.begin(), records.end(), [&](const AgentRecord& record) {
    return record.alive && record.kind == kind &&
           std::find(record.owns.begin(), record.owns.end(), partition) != record.owns.end();
  });
  return owner == records.end() ? nullptr : &*owner;
}

AgentDirectory::AgentDirectory(Participant& participant, AgentDirectoryOptions options)
    : participant_(participant), options_(std::move(options)) {}

Result<std::unique_ptr<AgentDirectory>> AgentDirectory::create(Participant& participant,
                                                               AgentDirectoryOptions options) {
  std::unique_ptr<AgentDirectory> self(new AgentDirectory(participant, std::move(options)));
  AgentDirectory* directory = self.get();
  directory->events_token_ = participant.subscribe_events(
      [directory](const ParticipantEvent& event) { directory->on_participant_event(event); });

  TopicQos qos = TopicQos::state();
  qos.deadline = directory->options_.deadline;
  detail::ReaderSpec spec{kHeartbeatTopic, type_support<msg::Heartbeat>(), qos, {}, {}, {},
                          detail::Dispatch::own_thread};
  auto reader = detail::ReaderCore::create(
      participant, std::move(spec),
      [directory](std::shared_ptr<void>& sample, const fdds::SampleInfo& info) {
        directory->on_heartbeat(*static_cast<const msg::Heartbeat*>(sample.get()), info);
      },
      [directory](const InstanceHandle_t& instance) { directory->on_deadline_missed(instance); });
  if (!reader) {
    participant.unsubscribe_events(directory->events_token_);
    return unexpected(reader.error());
  }
  std::lock_guard lock(directory->mutex_);
  directory->reader_ = std::move(*reader);
  return self;
}

AgentDirectory::~AgentDirectory() {
  participant_.unsubscribe_events(events_token_);
  std::unique_ptr<detail::ReaderCore> reader;
  {
    std::lock_guard lock(mutex_);
    reader = std::move(reader_);
  }
  reader.reset();
  notifier_.stop();
}

void AgentDirectory::on_heartbeat(const msg::Heartbeat& beat, const fdds::SampleInfo& info) {
  const GuidPrefix_t source = info.sample_identity.writer_guid().guidPrefix;
  std::lock_guard lock(mutex_);
  if (gone_participants_.count(source) > 0) {
    spdlog::debug("directory: heartbeat of '{}' from a gone participant ignored", beat.id());
    return;  // overtaken by its participant's end
  }
  id_by_instance_[info.instance_handle] = beat.id();
  Entry& entry = entries_[beat.id()];
  AgentRecord record{beat.id(), beat.kind(), beat.version(), beat.owns(), beat.sim_time().ns(), true, ""};
  if (entry.participant != source) spdlog::debug("directory: heartbeat of '{}' from a new participant", beat.id());
  entry.participant = source;
  // Only the sim_time changes with every beat: changes of anything else are announced.
  const bool changed = !entry.record.alive || entry.record.kind != record.kind ||
                       entry.record.version != record.version || entry.record.owns != record.owns;
  entry.record = std::move(record);
  if (changed) {
    spdlog::debug("directory: '{}' ({}) alive", beat.id(), beat.kind());
    publish_change_locked(entry.record);
  }
}

void AgentDirectory::on_deadline_missed(const InstanceHandle_t& instance) {
  std::lock_guard lock(mutex_);
  auto it = id_by_instance_.find(instance);
  if (it == id_by_instance_.end()) return;
  mark_dead_locked(it->second, "heartbeat deadline missed");
}

void AgentDirectory::on_participant_event(const ParticipantEvent& event) {
  spdlog::debug("directory: participant '{}' {}", event.name,
                event.change == ParticipantChange::discovered ? "discovered"
                : event.change == ParticipantChange::dropped  ? "dropped"
                                                              : "removed");
  if (event.change == ParticipantChange::discovered) {
    // A participant dropped under load (its announcements missed for a lease) and then
    // heard again is back: its heartbeats count again. Kept among the gone, its agent
    // stayed dead for good (a restarted topology agent ignored by every logical agent).
    std::lock_guard lock(mutex_);
    gone_participants_.erase(event.guid_prefix);
    return;
  }
  const std::string reason =
      event.change == ParticipantChange::dropped ? "participant dropped" : "participant removed";
  std::lock_guard lock(mutex_);
  gone_participants_.insert(event.guid_prefix);
  for (auto& [id, entry] : entries_) {
    if (entry.participant == event.guid_prefix) mark_dead_locked(id, reason);
  }
}

void AgentDirectory::mark_dead_locked(const std::string& id, const std::string& reason) {
  auto it = entries_.find(id);
  if (it == entries_.end() || !it->second.record.alive) return;
  it->second.record.alive = false;
  it->second.record.lost_reason = reason;
  spdlog::debug("directory: '{}' dead ({})", id, reason);
  publish_change_locked(it->second.record);
}

void AgentDirectory::publish_change_locked(const AgentRecord& record) {
  changed_.notify_all();
  if (options_.on_change) {
    notifier_.post([this, record] { options_.on_change(record); });
  }
}

std::vector<AgentRecord> AgentDirectory::agents_locked() const {
  std::vector<AgentRecord> out;
  out.reserve(entries_.size());
  for (const auto& [id, entry] : entries_) out.push_back(entry.record);
  return out;  // std::map keeps them sorted by id
}

std::vector<AgentRecord> AgentDirectory::agents() const {
  std::lock_guard lock(mutex_);
  return agents_locked();
}

std::vector<AgentRecord> AgentDirectory::live_agents() const {
  std::vector<AgentRecord> out = agents();
  out.erase(std::remove_if(out.begin(), out.end(), [](const AgentRecord& r) { return !r.alive; }),
            out.end());
  return out;
}

std::optional<AgentRecord> AgentDirectory::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  if (auto it = entries_.find(id); it != entries_.end()) return it->second.record;
  return std::nullopt;
}

std::optional<AgentRecord> AgentDirectory::live_owner_of(std::string_view kind, std::string_view partition) const {
  std::lock_guard lock(mutex_);
  std::vector<AgentRecord> records = agents_locked();
  const AgentRecord* owner = live_owner_among(records, kind, partition);
  return owner ? std::optional<AgentRecord>(*owner) : std::nullopt;
}

bool AgentDirectory::wait_until(const std::function<bool(const std::vector<AgentRecord>&)>& predicate,
                                std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return predicate(agents_locked()); });
}

bool AgentDirectory::wait_for_agent(const std::string& id, bool alive,
                                    std::chrono::milliseconds timeout) const {
  return wait_until(
      [&](const std::vector<AgentRecord>& records) {
        return std::any_of(records.begin(), records.end(),
                           [&](const AgentRecord& r) { return r.id == id && r.alive == alive; });
      },
      timeout);
}

}  // namespace drover::dds

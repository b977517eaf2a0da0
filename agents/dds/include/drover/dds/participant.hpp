#pragma once
// One DDS domain participant per agent, named after the agent id. It registers the message
// types, owns the topics, one publisher and one subscriber, and reports which remote
// participants (agents) come and go.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/GuidPrefix_t.hpp>

#include "drover/common/result.hpp"
#include "drover/dds/message_types.hpp"

namespace drover::dds {

namespace detail {
class DiscoveryListener;
}

struct ParticipantOptions {
  /// DDS domain id (0..232); agents of one deployment share it, tests use one each.
  std::uint32_t domain_id = 0;
  /// The agent id, which is also the participant name; see validate_agent_id().
  std::string agent_id;
  /// A Fast DDS XML profiles file to load first (transports, locators, security);
  /// empty: none. FASTRTPS_DEFAULT_PROFILES_FILE is honoured by Fast DDS either way.
  std::string xml_profile_file;
  /// A participant profile of the loaded XML to start from; empty: the default profile.
  std::string profile_name;
  /// How long a remote participant that stopped announcing itself (killed, cut off) is
  /// still considered present; a shorter lease detects dead agents sooner.
  std::chrono::milliseconds lease_duration{3000};
  /// How often this participant announces itself; must be shorter than the lease.
  std::chrono::milliseconds announcement_period{1000};
};

/// What happened to a remote participant.
enum class ParticipantChange { discovered, removed, dropped };

struct ParticipantEvent {
  ParticipantChange change;
  std::string name;  ///< the participant name, which is the remote agent's id
  eprosima::fastrtps::rtps::GuidPrefix_t guid_prefix;
};

/// Agent ids name participants, appear in content filters and in lock ids, so they are
/// restricted to 1..64 characters of [A-Za-z0-9_.-].
/// \return success, or invalid_argument naming the offending character.
Status validate_agent_id(std::string_view agent_id);

/// Thread-safe. Contract: every Writer, Reader, ServiceClient, ServiceServer,
/// HeartbeatPublisher and AgentDirectory created on a Participant is destroyed before it.
class Participant {
 public:
  /// Creates and enables the participant.
  /// \return the participant, or invalid_argument (bad agent id, lease not longer than
  ///         the announcement period, unreadable XML file, unknown profile) or
  ///         unavailable (Fast DDS refused to create it: see its log).
  static Result<std::unique_ptr<Participant>> create(const ParticipantOptions& options);

  /// Deletes every entity still contained (publishers, subscribers, topics), then the
  /// participant itself.
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  const std::string& agent_id() const noexcept { return agent_id_; }
  std::uint32_t domain_id() const noexcept { return domain_id_; }

  eprosima::fastdds::dds::DomainParticipant& native() noexcept { return *participant_; }
  eprosima::fastdds::dds::Publisher& publisher() noexcept { return *publisher_; }
  eprosima::fastdds::dds::Subscriber& subscriber() noexcept { return *subscriber_; }

  /// The topic `name` carrying T, created on first use and shared afterwards.
  /// \return the topic, or conflict when `name` already carries another type.
  template <class T>
  Result<eprosima::fastdds::dds::Topic*> topic(const std::string& name) {
    return find_or_create_topic(name, type_support<T>());
  }
  /// As topic<T>(), for type-erased callers; registers `type` on first use.
  Result<eprosima::fastdds::dds::Topic*> find_or_create_topic(
      const std::string& name, eprosima::fastdds::dds::TypeSupport type);

  /// A new content-filtered view of `related`. With an empty `filter_class`, Fast DDS's
  /// default SQL-like filter (parameters as it wants them: strings single-quoted); or a
  /// class registered on every Participant (detail::kRequesterFilterClass). The caller
  /// deletes it with delete_filtered_topic() after the readers that use it.
  /// \return the topic, or invalid_argument when Fast DDS rejects the expression.
  Result<eprosima::fastdds::dds::ContentFilteredTopic*> create_filtered_topic(
      eprosima::fastdds::dds::Topic& related, const std::string& expression,
      const std::vector<std::string>& parameters, const std::string& filter_class = {});
  void delete_filtered_topic(eprosima::fastdds::dds::ContentFilteredTopic* topic);

  /// The name of a participant seen by discovery (or of this one), if known.
  std::optional<std::string> participant_name(
      const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const;

  using EventHandler = std::function<void(const ParticipantEvent&)>;
  /// Calls `handler` for every later participant event, on Fast DDS's discovery thread:
  /// it must return quickly and must not call unsubscribe_events().
  /// \return a token for unsubscribe_events().
  std::uint64_t subscribe_events(EventHandler handler);
  /// After this returns, the handler is not running and is never called again.
  void unsubscribe_events(std::uint64_t token);

 private:
  friend class detail::DiscoveryListener;
  explicit Participant(const ParticipantOptions& options);
  void on_discovery(const ParticipantEvent& event);

  std::string agent_id_;
  std::uint32_t domain_id_;
  std::unique_ptr<detail::DiscoveryListener> listener_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;

  std::mutex topics_mutex_;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::uint64_t filtered_topic_count_ = 0;

  mutable std::mutex discovery_mutex_;
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, std::string> names_;
  std::map<std::uint64_t, EventHandler> handlers_;
  std::uint64_t next_token_ = 1;
};

}  // namespace drover::dds

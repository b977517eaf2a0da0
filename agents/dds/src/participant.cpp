#include "drover/dds/participant.hpp"

#include <cctype>
#include <filesystem>
#include <memory>
#include <utility>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/rtps/participant/ParticipantDiscoveryInfo.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <spdlog/spdlog.h>

#include "drover/dds/detail/requester_filter.hpp"

namespace drover::dds {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

namespace detail {

/// Forwards participant discovery to the Participant. Installed with StatusMask::none()
/// so that it never takes data or matching callbacks away from the endpoints' listeners
/// (Fast DDS calls on_participant_discovery regardless of the mask).
class DiscoveryListener final : public fdds::DomainParticipantListener {
 public:
  explicit DiscoveryListener(Participant& owner) : owner_(owner) {}

  void on_participant_discovery(fdds::DomainParticipant*,
                                ParticipantDiscoveryInfo&& info) override {
    ParticipantChange change;
    switch (info.status) {
      case ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT:
        change = ParticipantChange::discovered;
        break;
      case ParticipantDiscoveryInfo::REMOVED_PARTICIPANT:
        change = ParticipantChange::removed;
        break;
      case ParticipantDiscoveryInfo::DROPPED_PARTICIPANT:
        change = ParticipantChange::dropped;
        break;
      default:
        return;  // CHANGED_QOS_PARTICIPANT: the name and the presence are unchanged
    }
    owner_.on_discovery(
        ParticipantEvent{change, info.info.m_participantName.to_string(), info.info.m_guid.guidPrefix});
  }

 private:
  Participant& owner_;
};

}  // namespace detail

namespace {

eprosima::fastrtps::Duration_t to_duration(std::chrono::milliseconds ms) {
  return eprosima::fastrtps::Duration_t(static_cast<long double>(ms.count()) / 1000.0L);
}

Result<fdds::DomainParticipantQos> participant_qos(const ParticipantOptions& options) {
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (!options.xml_profile_file.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(options.xml_profile_file, ec)) {
      return fail(ErrorCode::invalid_argument,
                  "DDS XML profile file '" + options.xml_profile_file + "' does not exist");
    }
    if (factory->load_XML_profiles_file(options.xml_profile_file) != ReturnCode_t::RETCODE_OK) {
      return fail(ErrorCode::invalid_argument, "cannot load DDS XML profile file '" +
                                                   options.xml_profile_file +
                                                   "' (Fast DDS logged why)");
    }
  }
  fdds::DomainParticipantQos qos = factory->get_default_participant_qos();
  if (!options.profile_name.empty() &&
      factory->get_participant_qos_from_profile(options.profile_name, qos) != ReturnCode_t::RETCODE_OK) {
    return fail(ErrorCode::invalid_argument,
                "no DDS participant profile named '" + options.profile_name + "'");
  }
  qos.name(options.agent_id);
  if (options.xml_profile_file.empty() && qos.transport().use_builtin_transports &&
      qos.transport().user_transports.empty()) {
    // UDPv4 only, not Fast DDS's default of shared memory + UDP: 2.9's shared-memory
    // transport loses the traffic to a process restarted after a crash that gets its
    // predecessor's port (it replaces the dead port's segment while the others keep
    // writing into the old one), so nobody heard a restarted topology agent again. An XML
    // profile file sets the transports as it likes.
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  }
  auto& discovery = qos.wire_protocol().builtin.discovery_config;
  discovery.leaseDuration = to_duration(options.lease_duration);
  discovery.leaseDuration_announcementperiod = to_duration(options.announcement_period);
  return qos;
}

}  // namespace

Status validate_agent_id(std::string_view agent_id) {
  if (agent_id.empty()) return fail(ErrorCode::invalid_argument, "agent id is empty");
  if (agent_id.size() > 64) {
    return fail(ErrorCode::invalid_argument,
                "agent id '" + std::string(agent_id) + "' is longer than 64 characters");
  }
  for (std::size_t i = 0; i < agent_id.size(); ++i) {
    const char c = agent_id[i];
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '_' && c != '.' && c != '-') {
      return fail(ErrorCode::invalid_argument,
                  "agent id '" + std::string(agent_id) + "' has character '" + std::string(1, c) +
                      "' at position " + std::to_string(i) + " (allowed: A-Z a-z 0-9 _ . -)");
    }
  }
  return {};
}

Participant::Participant(const ParticipantOptions& options)
    : agent_id_(options.agent_id), domain_id_(options.domain_id) {}

Result<std::unique_ptr<Participant>> Participant::create(const ParticipantOptions& options) {
  if (auto valid = validate_agent_id(options.agent_id); !valid) return unexpected(valid.error());
  if (options.domain_id > 232) {
    return fail(ErrorCode::invalid_argument,
                "DDS domain id " + std::to_string(options.domain_id) + " is out of range 0..232");
  }
  if (options.announcement_period.count() <= 0 ||
      options.lease_duration <= options.announcement_period) {
    return fail(ErrorCode::invalid_argument,
                "participant lease (" + std::to_string(options.lease_duration.count()) +
                    " ms) must be longer than its announcement period (" +
                    std::to_string(options.announcement_period.count()) + " ms), which must be positive");
  }
  auto qos = participant_qos(options);
  if (!qos) return unexpected(qos.error());
  register_type_objects();

  std::unique_ptr<Participant> self(new Participant(options));
  self->listener_ = std::make_unique<detail::DiscoveryListener>(*self);
  self->participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<fdds::DomainId_t>(options.domain_id), *qos, self->listener_.get(),
      fdds::StatusMask::none());
  if (self->participant_ == nullptr) {
    return fail(ErrorCode::unavailable, "Fast DDS could not create participant '" +
                                            options.agent_id + "' on domain " +
                                            std::to_string(options.domain_id));
  }
  {
    std::lock_guard lock(self->discovery_mutex_);
    self->names_[self->participant_->guid().guidPrefix] = options.agent_id;
  }
  if (self->participant_->register_content_filter_factory(
          detail::kRequesterFilterClass, &detail::RequesterFilterFactory::instance()) !=
      ReturnCode_t::RETCODE_OK) {
    return fail(ErrorCode::internal, "cannot register the requester content filter");
  }
  self->publisher_ = self->participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  // Readers are created disabled and enabled once their owner holds them: Fast DDS may
  // otherwise call a reader's listener before create_datareader() has returned.
  fdds::SubscriberQos subscriber_qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  subscriber_qos.entity_factory().autoenable_created_entities = false;
  self->subscriber_ = self->participant_->create_subscriber(subscriber_qos);
  if (self->publisher_ == nullptr || self->subscriber_ == nullptr) {
    return fail(ErrorCode::unavailable,
                "Fast DDS could not create the publisher or subscriber of '" + options.agent_id + "'");
  }
  return self;
}

Participant::~Participant() {
  if (participant_ == nullptr) return;
  // Endpoints are gone by contract; this removes the publisher, subscriber and topics.
  if (participant_->delete_contained_entities() != ReturnCode_t::RETCODE_OK) {
    spdlog::error("participant '{}': could not delete its DDS entities", agent_id_);
  }
  participant_->set_listener(nullptr);
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

Result<fdds::Topic*> Participant::find_or_create_topic(const std::string& name,
                                                       fdds::TypeSupport type) {
  std::lock_guard lock(topics_mutex_);
  const std::string type_name = type.get_type_name();
  if (auto it = topics_.find(name); it != topics_.end()) {
    if (it->second->get_type_name() != type_name) {
      return fail(ErrorCode::conflict, "topic '" + name + "' carries " +
                                           it->second->get_type_name() + ", not " + type_name);
    }
    return it->second;
  }
  if (participant_->find_type(type_name).empty() &&
      type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
    return fail(ErrorCode::internal, "cannot register DDS type " + type_name);
  }
  fdds::Topic* topic = participant_->create_topic(name, type_name, fdds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) {
    return fail(ErrorCode::invalid_argument, "Fast DDS refused to create topic '" + name + "'");
  }
  topics_.emplace(name, topic);
  return topic;
}

Result<fdds::ContentFilteredTopic*> Participant::create_filtered_topic(
    fdds::Topic& related, const std::string& expression, const std::vector<std::string>& parameters,
    const std::string& filter_class) {
  std::string name;
  {
    std::lock_guard lock(topics_mutex_);
    name = related.get_name() + "#filtered" + std::to_string(++filtered_topic_count_);
  }
  fdds::ContentFilteredTopic* topic =
      filter_class.empty()
          ? participant_->create_contentfilteredtopic(name, &related, expression, parameters)
          : participant_->create_contentfilteredtopic(name, &related, expression, parameters,
                                                      filter_class.c_str());
  if (topic == nullptr) {
    return fail(ErrorCode::invalid_argument, "Fast DDS rejected the content filter '" + expression +
                                                 "' on topic '" + related.get_name() + "'");
  }
  return topic;
}

void Participant::delete_filtered_topic(fdds::ContentFilteredTopic* topic) {
  if (topic != nullptr && participant_->delete_contentfilteredtopic(topic) != ReturnCode_t::RETCODE_OK) {
    spdlog::error("participant '{}': could not delete filtered topic '{}'", agent_id_,
                  topic->get_name());
  }
}

std::optional<std::string> Participant::participant_name(const GuidPrefix_t& prefix) const {
  std::lock_guard lock(discovery_mutex_);
  if (auto it = names_.find(prefix); it != names_.end()) return it->second;
  return std::nullopt;
}

std::uint64_t Participant::subscribe_events(EventHandler handler) {
  std::lock_guard lock(discovery_mutex_);
  const std::uint64_t token = next_token_++;
  handlers_.emplace(token, std::move(handler));
  return token;
}

void Participant::unsubscribe_events(std::uint64_t token) {
  std::lock_guard lock(discovery_mutex_);
  handlers_.erase(token);
}

void Participant::on_discovery(const ParticipantEvent& event) {
  std::lock_guard lock(discovery_mutex_);
  if (event.change == ParticipantChange::discovered) {
    names_[event.guid_prefix] = event.name;
  } else {
    names_.erase(event.guid_prefix);
  }
  for (auto& [token, handler] : handlers_) handler(event);
}

}  // namespace drover::dds

#include "drover/dds/detail/writer_core.hpp"

#include <utility>

#include <fastdds/dds/publisher/Publisher.hpp>
#include <spdlog/spdlog.h>

namespace drover::dds::detail {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using eprosima::fastrtps::rtps::GuidPrefix_t;

WriterCore::WriterCore(Participant& participant, std::string topic, MatchHook hook)
    : participant_(participant), topic_name_(std::move(topic)), hook_(std::move(hook)) {}

Result<std::unique_ptr<WriterCore>> WriterCore::create(Participant& participant,
                                                       const std::string& topic,
                                                       fdds::TypeSupport type,
                                                       const TopicQos& qos, MatchHook hook) {
  auto dds_topic = participant.find_or_create_topic(topic, std::move(type));
  if (!dds_topic) return unexpected(dds_topic.error());
  std::unique_ptr<WriterCore> self(new WriterCore(participant, topic, std::move(hook)));
  self->writer_ = participant.publisher().create_datawriter(
      *dds_topic, writer_qos(qos), self.get(), fdds::StatusMask::publication_matched());
  if (self->writer_ == nullptr) {
    return fail(ErrorCode::unavailable, "Fast DDS could not create a writer on '" + topic + "'");
  }
  return self;
}

WriterCore::~WriterCore() {
  if (writer_ != nullptr &&
      participant_.publisher().delete_datawriter(writer_) != ReturnCode_t::RETCODE_OK) {
    spdlog::error("could not delete the DDS writer on '{}'", topic_name_);
  }
}

Status WriterCore::write(void* sample) {
  if (!writer_->write(sample)) {
    return fail(ErrorCode::io, "could not write a sample on '" + topic_name_ + "'");
  }
  return {};
}

Status WriterCore::write(void* sample, eprosima::fastrtps::rtps::WriteParams& params) {
  if (!writer_->write(sample, params)) {
    return fail(ErrorCode::io, "could not write a sample on '" + topic_name_ + "'");
  }
  return {};
}

Status WriterCore::retire(void* sample) {
  // The writer's QoS keeps autodispose_unregistered_instances (the default): unregistering
  // disposes too, and Fast DDS drops the instance's samples once every reader acknowledged.
  const ReturnCode_t code = writer_->unregister_instance(sample, fdds::HANDLE_NIL);
  if (code == ReturnCode_t::RETCODE_OK) return {};
  if (code == ReturnCode_t::RETCODE_PRECONDITION_NOT_MET) {
    return fail(ErrorCode::not_found, "no instance of that key was written on '" + topic_name_ + "'");
  }
  return fail(ErrorCode::io, "could not retire an instance on '" + topic_name_ + "'");
}

bool WriterCore::matched(const GuidPrefix_t& participant) const {
  std::lock_guard lock(mutex_);
  return matched_.contains(participant);
}

bool WriterCore::matched(const eprosima::fastrtps::rtps::GUID_t& reader) const {
  std::lock_guard lock(mutex_);
  return matched_.contains(reader);
}

std::vector<GuidPrefix_t> WriterCore::matched_participants() const {
  std::lock_guard lock(mutex_);
  return matched_.participants();
}

std::size_t WriterCore::matched_readers() const {
  std::lock_guard lock(mutex_);
  return matched_.size();
}

bool WriterCore::wait_for_readers(std::size_t count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return matched_changed_.wait_for(lock, timeout, [&] { return matched_.size() >= count; });
}

void WriterCore::on_publication_matched(fdds::DataWriter*,
                                        const fdds::PublicationMatchedStatus& status) {
  {
    std::lock_guard lock(mutex_);
    matched_.update(status.last_subscription_handle, status.current_count_change);
  }
  matched_changed_.notify_all();
  if (hook_) hook_();
}

}  // namespace drover::dds::detail

#include "drover/dds/detail/reader_core.hpp"

#include <utility>

#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <spdlog/spdlog.h>

namespace drover::dds::detail {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using eprosima::fastrtps::rtps::GuidPrefix_t;

ReaderCore::ReaderCore(Participant& participant, ReaderSpec spec, SampleHandler on_sample,
                       DeadlineHandler on_deadline, MatchHook on_match)
    : participant_(participant),
      spec_(std::move(spec)),
      on_sample_(std::move(on_sample)),
      on_deadline_(std::move(on_deadline)),
      on_match_(std::move(on_match)) {
  if (spec_.dispatch == Dispatch::own_thread) executor_.emplace();
  buffer_ = new_buffer();
}

Result<std::unique_ptr<ReaderCore>> ReaderCore::create(Participant& participant, ReaderSpec spec,
                                                       SampleHandler on_sample,
                                                       DeadlineHandler on_deadline,
                                                       MatchHook on_match) {
  auto topic = participant.find_or_create_topic(spec.topic, spec.type);
  if (!topic) return unexpected(topic.error());
  std::unique_ptr<ReaderCore> self(new ReaderCore(participant, std::move(spec), std::move(on_sample),
                                                  std::move(on_deadline), std::move(on_match)));
  fdds::TopicDescription* description = *topic;
  if (!self->spec_.filter_expression.empty()) {
    auto filtered = participant.create_filtered_topic(**topic, self->spec_.filter_expression,
                                                      self->spec_.filter_parameters,
                                                      self->spec_.filter_class);
    if (!filtered) return unexpected(filtered.error());
    self->filtered_topic_ = *filtered;
    description = *filtered;
  }
  fdds::StatusMask mask = fdds::StatusMask::data_available() << fdds::StatusMask::subscription_matched();
  if (self->on_deadline_) mask << fdds::StatusMask::requested_deadline_missed();
  self->reader_ = participant.subscriber().create_datareader(description, reader_qos(self->spec_.qos),
                                                             self.get(), mask);
  if (self->reader_ == nullptr) {
    return fail(ErrorCode::unavailable,
                "Fast DDS could not create a reader on '" + self->spec_.topic + "'");
  }
  // Created disabled (see Participant::create): no callback ran before reader_ was set.
  if (self->reader_->enable() != ReturnCode_t::RETCODE_OK) {
    return fail(ErrorCode::unavailable,
                "Fast DDS could not enable the reader on '" + self->spec_.topic + "'");
  }
  return self;
}

ReaderCore::~ReaderCore() {
  if (executor_) executor_->stop();
  if (reader_ != nullptr &&
      participant_.subscriber().delete_datareader(reader_) != ReturnCode_t::RETCODE_OK) {
    spdlog::error("could not delete the DDS reader on '{}'", spec_.topic);
  }
  participant_.delete_filtered_topic(filtered_topic_);
}

std::shared_ptr<void> ReaderCore::new_buffer() const {
  fdds::TypeSupport type = spec_.type;
  return std::shared_ptr<void>(type.create_data(), [type](void* data) mutable { type.delete_data(data); });
}

void ReaderCore::take_all() {
  std::lock_guard lock(take_mutex_);
  take_scheduled_ = false;
  fdds::SampleInfo info;
  while (reader_->take_next_sample(buffer_.get(), &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;  // instance state changes carry no sample
    on_sample_(buffer_, info);
    if (!buffer_) buffer_ = new_buffer();
  }
}

void ReaderCore::on_data_available(fdds::DataReader*) {
  if (!executor_) {
    take_all();
    return;
  }
  // One queued take loop at a time is enough: it takes everything available.
  if (!take_scheduled_.exchange(true)) executor_->post([this] { take_all(); });
}

void ReaderCore::on_subscription_matched(fdds::DataReader*,
                                         const fdds::SubscriptionMatchedStatus& status) {
  {
    std::lock_guard lock(match_mutex_);
    matched_.update(status.last_publication_handle, status.current_count_change);
  }
  spdlog::debug("reader on '{}': {} writer(s) matched ({:+})", spec_.topic, status.current_count,
                status.current_count_change);
  match_changed_.notify_all();
  if (on_match_) on_match_();
}

void ReaderCore::on_requested_deadline_missed(fdds::DataReader*,
                                              const fdds::RequestedDeadlineMissedStatus& status) {
  if (!on_deadline_) return;
  if (!executor_) {
    on_deadline_(status.last_instance_handle);
    return;
  }
  executor_->post([this, instance = status.last_instance_handle] { on_deadline_(instance); });
}

bool ReaderCore::matched(const GuidPrefix_t& participant) const {
  std::lock_guard lock(match_mutex_);
  return matched_.contains(participant);
}

std::vector<GuidPrefix_t> ReaderCore::matched_participants() const {
  std::lock_guard lock(match_mutex_);
  return matched_.participants();
}

std::size_t ReaderCore::matched_writers() const {
  std::lock_guard lock(match_mutex_);
  return matched_.size();
}

bool ReaderCore::wait_for_writers(std::size_t count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(match_mutex_);
  return match_changed_.wait_for(lock, timeout, [&] { return matched_.size() >= count; });
}

}  // namespace drover::dds::detail

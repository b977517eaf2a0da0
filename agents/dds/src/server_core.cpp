#include "drover/dds/detail/server_core.hpp"

#include <utility>

#include <fastdds/rtps/common/WriteParams.h>

namespace drover::dds::detail {

namespace fdds = eprosima::fastdds::dds;

ReplyChannel::ReplyChannel(std::string service_name, std::chrono::milliseconds match_timeout)
    : service_name_(std::move(service_name)), match_timeout_(match_timeout) {}

ReplyChannel::~ReplyChannel() { close(); }

void ReplyChannel::attach(std::unique_ptr<WriterCore> writer) {
  {
    std::lock_guard lock(mutex_);
    writer_ = std::move(writer);
  }
  match_changed_.notify_all();
}

void ReplyChannel::close() {
  std::unique_ptr<WriterCore> writer;
  {
    std::lock_guard lock(mutex_);
    writer = std::move(writer_);
  }
  match_changed_.notify_all();
  writer.reset();  // outside the lock: its match hook takes the lock
}

void ReplyChannel::notify_match_change() {
  { std::lock_guard lock(mutex_); }  // orders the notification after the waiter's check
  match_changed_.notify_all();
}

Status ReplyChannel::write(void* reply, const ReplyTarget& target) {
  std::unique_lock lock(mutex_);
  const bool matched = match_changed_.wait_for(lock, match_timeout_, [&] {
    if (writer_ == nullptr) return true;
    const auto& reader = target.reply_reader;
    return reader.entityId == eprosima::fastrtps::rtps::c_EntityId_Unknown ? writer_->matched(reader.guidPrefix)
                                                                           : writer_->matched(reader);
  });
  if (writer_ == nullptr) {
    return fail(ErrorCode::unavailable,
                "service '" + service_name_ + "' was closed before its reply to '" + target.requester +
                    "' was sent");
  }
  if (!matched) {
    return fail(ErrorCode::timeout, "reply of '" + service_name_ + "' to '" + target.requester +
                                        "' not sent: its reply reader did not match within " +
                                        std::to_string(match_timeout_.count()) + " ms");
  }
  eprosima::fastrtps::rtps::WriteParams params;
  params.related_sample_identity(target.request);
  return writer_->write(reply, params);
}

Result<std::unique_ptr<ServerCore>> ServerCore::create(Participant& participant, ServiceTopics topics,
                                                       fdds::TypeSupport request_type,
                                                       fdds::TypeSupport reply_type,
                                                       std::chrono::milliseconds reply_match_timeout,
                                                       RequestHandler handler) {
  std::unique_ptr<ServerCore> self(new ServerCore());
  self->channel_ = std::make_shared<ReplyChannel>(topics.name, reply_match_timeout);
  ReplyChannel* channel = self->channel_.get();  // owns the writer, so outlives its hook
  auto writer = WriterCore::create(participant, topics.reply, std::move(reply_type),
                                   TopicQos::service(), [channel] { channel->notify_match_change(); });
  if (!writer) return unexpected(writer.error());
  self->channel_->attach(std::move(*writer));

  ReaderSpec request_spec{topics.request, std::move(request_type), TopicQos::service(), {}, {}, {},
                          Dispatch::own_thread};
  auto reader = ReaderCore::create(
      participant, std::move(request_spec),
      [handler = std::move(handler), channel = self->channel_](std::shared_ptr<void>& request,
                                                               const fdds::SampleInfo& info) {
        handler(request.get(), info, channel);
      });
  if (!reader) return unexpected(reader.error());
  self->request_reader_ = std::move(*reader);
  return self;
}

ServerCore::~ServerCore() {
  request_reader_.reset();
  if (channel_) channel_->close();
}

std::size_t ServerCore::matched_clients() const { return request_reader_->matched_writers(); }

}  // namespace drover::dds::detail

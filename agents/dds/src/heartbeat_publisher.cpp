#include "drover/dds/heartbeat_publisher.hpp"

#include <utility>

#include <spdlog/spdlog.h>

namespace drover::dds {

HeartbeatPublisher::HeartbeatPublisher(Participant& participant, SharedClock clock,
                                       HeartbeatOptions options,
                                       std::unique_ptr<Writer<msg::Heartbeat>> writer)
    : agent_id_(participant.agent_id()),
      clock_(clock),
      options_(std::move(options)),
      writer_(std::move(writer)),
      thread_([this] { run(); }) {}

Result<std::unique_ptr<HeartbeatPublisher>> HeartbeatPublisher::create(Participant& participant,
                                                                       SharedClock clock,
                                                                       HeartbeatOptions options) {
  if (options.kind.empty()) return fail(ErrorCode::invalid_argument, "heartbeat: agent kind is empty");
  if (options.period.count() <= 0 || options.period * 2 > options.deadline) {
    return fail(ErrorCode::invalid_argument,
                "heartbeat period (" + std::to_string(options.period.count()) +
                    " ms) must be positive and at most half the deadline (" +
                    std::to_string(options.deadline.count()) + " ms)");
  }
  if (options.version.empty()) options.version = DROVER_VERSION;
  TopicQos qos = TopicQos::state();
  qos.deadline = options.deadline;
  auto writer = Writer<msg::Heartbeat>::create(participant, kHeartbeatTopic, qos);
  if (!writer) return unexpected(writer.error());
  return std::unique_ptr<HeartbeatPublisher>(
      new HeartbeatPublisher(participant, clock, std::move(options), std::move(*writer)));
}

HeartbeatPublisher::~HeartbeatPublisher() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void HeartbeatPublisher::set_owns(std::vector<std::string> owns) {
  {
    std::lock_guard lock(mutex_);
    options_.owns = std::move(owns);
    owns_changed_ = true;
  }
  wake_.notify_all();
}

void HeartbeatPublisher::run() {
  msg::Heartbeat beat;
  beat.id(agent_id_);
  beat.kind(options_.kind);
  beat.version(options_.version);
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    beat.owns(options_.owns);
    owns_changed_ = false;
    msg::Time now;
    now.ns(clock_.now());
    beat.sim_time(now);
    lock.unlock();
    if (auto written = writer_->write(beat); !written) {
      spdlog::error("heartbeat of '{}': {}", agent_id_, written.error().message);
    }
    lock.lock();
    // A timer, not synchronisation: the next beat is due one period later.
    wake_.wait_for(lock, options_.period, [this] { return stopping_ || owns_changed_; });
  }
}

}  // namespace drover::dds

#pragma once
// Every agent publishes one Heartbeat instance, keyed on its id, on drover/agents/heartbeat
// (RELIABLE + TRANSIENT_LOCAL + KEEP_LAST 1, with a deadline). AgentDirectory reads them.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drover/common/clock.hpp"
#include "drover/common/result.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/writer.hpp"
#include "heartbeat.h"

namespace drover::dds {

inline constexpr const char* kHeartbeatTopic = "drover/agents/heartbeat";
/// The deadline every heartbeat writer offers and every directory requests, unless a
/// deployment configures another one everywhere (a reader whose deadline is shorter than
/// a writer's does not match it).
inline constexpr std::chrono::milliseconds kHeartbeatDeadline{2000};

struct HeartbeatOptions {
  /// What the agent is: topology, routing, logical, ran, fleet, droverctl, ...
  std::string kind;
  /// Its software version; empty: Drover's version.
  std::string version;
  /// What it owns: partitions, entity ids, vehicle ids.
  std::vector<std::string> owns;
  /// Time between beats; must be at most half the deadline.
  std::chrono::milliseconds period{500};
  std::chrono::milliseconds deadline = kHeartbeatDeadline;
};

/// Publishes the participant's agent heartbeat from its own thread until destroyed.
/// Thread-safe. Must be destroyed before its Participant.
class HeartbeatPublisher {
 public:
  /// Starts beating at once. \return the publisher, or invalid_argument (empty kind,
  /// period not positive or longer than half the deadline), or the writer's errors.
  static Result<std::unique_ptr<HeartbeatPublisher>> create(Participant& participant,
                                                            SharedClock clock,
                                                            HeartbeatOptions options);
  /// Stops beating and deletes the writer. Readers learn of the end from the missed
  /// deadline (or the participant's removal), not from a disposal (see docs/dds.md).
  ~HeartbeatPublisher();

  /// Replaces what the agent owns; published with an immediate beat.
  void set_owns(std::vector<std::string> owns);

 private:
  HeartbeatPublisher(Participant& participant, SharedClock clock, HeartbeatOptions options,
                     std::unique_ptr<Writer<msg::Heartbeat>> writer);
  void run();

  std::string agent_id_;
  SharedClock clock_;
  HeartbeatOptions options_;
  std::unique_ptr<Writer<msg::Heartbeat>> writer_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool owns_changed_ = false;
  std::thread thread_;
};

}  // namespace drover::dds

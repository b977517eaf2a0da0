#pragma once
// One worker thread that runs posted tasks one at a time, in posting order. Endpoints use
// it so that user callbacks never run on Fast DDS's own threads: a callback may block or
// call a service (whose reply is delivered by a Fast DDS thread) without deadlocking.

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace drover::dds::detail {

class SerialExecutor {
 public:
  SerialExecutor();
  /// Stops the worker (see stop()).
  ~SerialExecutor();
  SerialExecutor(const SerialExecutor&) = delete;
  SerialExecutor& operator=(const SerialExecutor&) = delete;

  /// Queues a task; ignored once stop() has begun. Thread-safe.
  void post(std::function<void()> task);

  /// Discards queued tasks, waits for the running one to finish and joins the worker.
  /// Must not be called from a task (that would join the calling thread itself).
  void stop();

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace drover::dds::detail

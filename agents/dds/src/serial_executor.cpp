#include "drover/dds/detail/serial_executor.hpp"

#include <exception>
#include <utility>

#include <spdlog/spdlog.h>

namespace drover::dds::detail {

SerialExecutor::SerialExecutor() : worker_([this] { run(); }) {}

SerialExecutor::~SerialExecutor() { stop(); }

void SerialExecutor::post(std::function<void()> task) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    tasks_.push_back(std::move(task));
  }
  wake_.notify_one();
}

void SerialExecutor::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    tasks_.clear();
  }
  wake_.notify_one();
  if (worker_.joinable()) worker_.join();
}

void SerialExecutor::run() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !tasks_.empty(); });
      if (stopping_) return;
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    // A throwing callback is a bug in the agent; it is reported and the endpoint keeps
    // serving instead of terminating the process.
    try {
      task();
    } catch (const std::exception& e) {
      spdlog::error("DDS callback failed: {}", e.what());
    } catch (...) {
      spdlog::error("DDS callback failed with a non-standard exception");
    }
  }
}

}  // namespace drover::dds::detail

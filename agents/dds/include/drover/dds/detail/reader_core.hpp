#pragma once
// The type-erased part of a data reader: creation with Drover's QoS (optionally on a
// content-filtered view), taking samples and handing them to a handler, deadline misses,
// and which remote participants its writers belong to. Reader<T> and the services wrap it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "drover/common/result.hpp"
#include "drover/dds/detail/matched_endpoints.hpp"
#include "drover/dds/detail/serial_executor.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"

namespace drover::dds::detail {

/// Where handlers run.
enum class Dispatch {
  own_thread,       ///< on the reader's own worker thread: handlers may block or call services
  listener_thread,  ///< on Fast DDS's thread: handlers must only hand data over, quickly
};

struct ReaderSpec {
  std::string topic;
  eprosima::fastdds::dds::TypeSupport type;
  TopicQos qos;
  /// Content filter on the topic; empty: every sample. See
  /// Participant::create_filtered_topic for the class (empty: default SQL-like filter).
  std::string filter_expression;
  std::vector<std::string> filter_parameters;
  std::string filter_class;
  Dispatch dispatch = Dispatch::own_thread;
};

class ReaderCore final : private eprosima::fastdds::dds::DataReaderListener {
 public:
  /// Gets each valid sample in a buffer made by the type support. The handler may take
  /// the buffer (move it out); the reader then makes a new one.
  using SampleHandler =
      std::function<void(std::shared_ptr<void>& sample, const eprosima::fastdds::dds::SampleInfo&)>;
  /// Gets the instance whose requested deadline was missed.
  using DeadlineHandler = std::function<void(const eprosima::fastrtps::rtps::InstanceHandle_t&)>;
  /// Called after every match change, on a Fast DDS thread without internal locks held.
  using MatchHook = std::function<void()>;

  /// \return the reader, or invalid_argument (filter rejected), or the topic's error, or
  ///         unavailable (Fast DDS refused to create the reader).
  static Result<std::unique_ptr<ReaderCore>> create(Participant& participant, ReaderSpec spec,
                                                    SampleHandler on_sample,
                                                    DeadlineHandler on_deadline = {},
                                                    MatchHook on_match = {});
  /// Stops the worker, deletes the reader and its filtered topic; no handler or hook
  /// runs after this returns. Must not run inside one of this reader's own handlers.
  ~ReaderCore() override;

  bool matched(const eprosima::fastrtps::rtps::GuidPrefix_t& participant) const;
  std::vector<eprosima::fastrtps::rtps::GuidPrefix_t> matched_participants() const;
  std::size_t matched_writers() const;
  /// Waits until at least `count` writers are matched. \return whether they are.
  bool wait_for_writers(std::size_t count, std::chrono::milliseconds timeout) const;

  const eprosima::fastrtps::rtps::GUID_t& guid() const { return reader_->guid(); }
  const std::string& topic_name() const noexcept { return spec_.topic; }

 private:
  ReaderCore(Participant& participant, ReaderSpec spec, SampleHandler on_sample,
             DeadlineHandler on_deadline, MatchHook on_match);
  std::shared_ptr<void> new_buffer() const;
  void take_all();

  void on_data_available(eprosima::fastdds::dds::DataReader*) override;
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& status) override;
  void on_requested_deadline_missed(
      eprosima::fastdds::dds::DataReader*,
      const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& status) override;

  Participant& participant_;
  ReaderSpec spec_;
  SampleHandler on_sample_;
  DeadlineHandler on_deadline_;
  MatchHook on_match_;
  std::optional<SerialExecutor> executor_;  // only for Dispatch::own_thread
  std::atomic<bool> take_scheduled_{false};
  std::mutex take_mutex_;                   // one take loop at a time; guards buffer_
  std::shared_ptr<void> buffer_;
  eprosima::fastdds::dds::ContentFilteredTopic* filtered_topic_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  mutable std::mutex match_mutex_;
  mutable std::condition_variable match_changed_;
  MatchedEndpoints matched_;
};

}  // namespace drover::dds::detail

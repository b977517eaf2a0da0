#pragma once
// The type-erased part of a data writer: creation with Drover's QoS, writing, and which
// remote participants its readers belong to. Writer<T> and the services wrap it.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/WriteParams.h>

#include "drover/common/result.hpp"
#include "drover/dds/detail/matched_endpoints.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"

namespace drover::dds::detail {

class WriterCore final : private eprosima::fastdds::dds::DataWriterListener {
 public:
  /// Called (on a Fast DDS thread, without internal locks held) after every match change.
  using MatchHook = std::function<void()>;

  /// Creates the writer on topic `topic` (created on first use) of `type`.
  /// \return the writer, or the participant's topic error, or unavailable.
  static Result<std::unique_ptr<WriterCore>> create(Participant& participant,
                                                    const std::string& topic,
                                                    eprosima::fastdds::dds::TypeSupport type,
                                                    const TopicQos& qos, MatchHook hook = {});
  /// Deletes the DataWriter; no hook runs after this returns.
  ~WriterCore() override;

  /// Writes one sample. \return success, or io when Fast DDS could not (history full for
  /// longer than the blocking time, or the writer is broken).
  Status write(void* sample);
  /// Writes one sample with write parameters; on success params.sample_identity() holds
  /// the identity Fast DDS gave the sample.
  Status write(void* sample, eprosima::fastrtps::rtps::WriteParams& params);
  /// Disposes and unregisters the instance whose key `sample` carries (see Writer::retire).
  /// \return success, or not_found when this writer never wrote that instance (or retired
  ///         it already), or io when Fast DDS could not.
  Status retire(void* sample);

  /// Whether any reader of `participant` is matched.
  bool matched(const eprosima::fastrtps::rtps::GuidPrefix_t& participant) const;
  /// Whether the reader `reader` is matched.
  bool matched(const eprosima::fastrtps::rtps::GUID_t& reader) const;
  std::vector<eprosima::fastrtps::rtps::GuidPrefix_t> matched_participants() const;
  std::size_t matched_readers() const;
  /// Waits until at least `count` readers are matched. \return whether they are.
  bool wait_for_readers(std::size_t count, std::chrono::milliseconds timeout) const;

  const eprosima::fastrtps::rtps::GUID_t& guid() const { return writer_->guid(); }
  const std::string& topic_name() const noexcept { return topic_name_; }

 private:
  WriterCore(Participant& participant, std::string topic, MatchHook hook);
  void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                              const eprosima::fastdds::dds::PublicationMatchedStatus& status) override;

  Participant& participant_;
  std::string topic_name_;
  MatchHook hook_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  mutable std::mutex mutex_;
  mutable std::condition_variable matched_changed_;
  MatchedEndpoints matched_;
};

}  // namespace drover::dds::detail

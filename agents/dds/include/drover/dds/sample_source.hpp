#pragma once
// Which writer a sample came from. Two publishers of one key (two processes claiming one
// vehicle, say) look alike in the data; their writers' GUIDs tell them apart.

#include <string>

#include <fastdds/rtps/common/InstanceHandle.h>

namespace drover::dds {

class SampleSource {
 public:
  explicit SampleSource(const eprosima::fastrtps::rtps::InstanceHandle_t& writer) : writer_(writer) {}

  /// Equal for samples of one writer; a writer of another process, or of a later life of
  /// the same one, differs.
  friend bool operator==(const SampleSource& a, const SampleSource& b) { return a.writer_ == b.writer_; }

  /// The writer's GUID as Fast DDS prints it (participant prefix, then entity id).
  std::string text() const;

 private:
  eprosima::fastrtps::rtps::InstanceHandle_t writer_;
};

}  // namespace drover::dds

#pragma once
// The remote endpoints matched with one local endpoint, grouped by remote participant:
// request/reply needs to know that a given participant (agent) is matched, not just that
// someone is. Not thread-safe: the owning endpoint guards it.

#include <cstdint>
#include <map>
#include <vector>

#include <fastdds/rtps/common/GuidPrefix_t.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>

namespace drover::dds::detail {

class MatchedParticipants {
 public:
  /// Records that the remote endpoint `remote` matched (change > 0) or unmatched
  /// (change < 0), as reported by on_publication_matched / on_subscription_matched.
  void update(const eprosima::fastrtps::rtps::InstanceHandle_t& remote, std::int32_t change);

  bool contains(const eprosima::fastrtps::rtps::GuidPrefix_t& participant) const;
  /// The matched participants in GUID order.
  std::vector<eprosima::fastrtps::rtps::GuidPrefix_t> all() const;
  /// Number of matched remote endpoints.
  std::size_t endpoints() const noexcept { return endpoints_; }

 private:
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, std::int32_t> endpoints_per_participant_;
  std::size_t endpoints_ = 0;
};

}  // namespace drover::dds::detail

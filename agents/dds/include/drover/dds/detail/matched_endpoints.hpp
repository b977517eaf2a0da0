#pragma once
// The remote endpoints matched with one local endpoint. Request/reply needs to know that
// a given participant (agent), or one given endpoint of it, is matched, not just that
// someone is. Not thread-safe: the owning endpoint guards it.

#include <cstdint>
#include <set>
#include <vector>

#include <fastdds/rtps/common/Guid.h>
#include <fastdds/rtps/common/InstanceHandle.h>

namespace drover::dds::detail {

class MatchedEndpoints {
 public:
  /// Records that the remote endpoint `remote` matched (change > 0) or unmatched
  /// (change < 0), as reported by on_publication_matched / on_subscription_matched.
  void update(const eprosima::fastrtps::rtps::InstanceHandle_t& remote, std::int32_t change);

  /// Whether any endpoint of `participant` is matched.
  bool contains(const eprosima::fastrtps::rtps::GuidPrefix_t& participant) const;
  /// Whether the endpoint `endpoint` is matched.
  bool contains(const eprosima::fastrtps::rtps::GUID_t& endpoint) const;
  /// The participants with a matched endpoint, in GUID order.
  std::vector<eprosima::fastrtps::rtps::GuidPrefix_t> participants() const;
  /// Number of matched remote endpoints.
  std::size_t size() const noexcept { return endpoints_.size(); }

 private:
  std::set<eprosima::fastrtps::rtps::GUID_t> endpoints_;
};

}  // namespace drover::dds::detail

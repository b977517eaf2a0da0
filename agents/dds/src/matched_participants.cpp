#include "drover/dds/detail/matched_participants.hpp"

namespace drover::dds::detail {

using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::iHandle2GUID;

void MatchedParticipants::update(const eprosima::fastrtps::rtps::InstanceHandle_t& remote,
                                 std::int32_t change) {
  const GuidPrefix_t prefix = iHandle2GUID(remote).guidPrefix;
  if (change > 0) {
    ++endpoints_per_participant_[prefix];
    ++endpoints_;
    return;
  }
  if (change < 0) {
    auto it = endpoints_per_participant_.find(prefix);
    if (it == endpoints_per_participant_.end()) return;
    --endpoints_;
    if (--it->second <= 0) endpoints_per_participant_.erase(it);
  }
}

bool MatchedParticipants::contains(const GuidPrefix_t& participant) const {
  return endpoints_per_participant_.count(participant) > 0;
}

std::vector<GuidPrefix_t> MatchedParticipants::all() const {
  std::vector<GuidPrefix_t> out;
  out.reserve(endpoints_per_participant_.size());
  for (const auto& [prefix, count] : endpoints_per_participant_) out.push_back(prefix);
  return out;
}

}  // namespace drover::dds::detail

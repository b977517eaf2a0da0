#include "drover/dds/detail/matched_endpoints.hpp"

namespace drover::dds::detail {

using eprosima::fastrtps::rtps::EntityId_t;
using eprosima::fastrtps::rtps::GUID_t;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::iHandle2GUID;

void MatchedEndpoints::update(const eprosima::fastrtps::rtps::InstanceHandle_t& remote, std::int32_t change) {
  if (change > 0) endpoints_.insert(iHandle2GUID(remote));
  if (change < 0) endpoints_.erase(iHandle2GUID(remote));
}

bool MatchedEndpoints::contains(const GuidPrefix_t& participant) const {
  // GUIDs order by prefix first, and no entity id is below the unknown one (all zeros).
  auto first = endpoints_.lower_bound(GUID_t(participant, EntityId_t()));
  return first != endpoints_.end() && first->guidPrefix == participant;
}

bool MatchedEndpoints::contains(const GUID_t& endpoint) const { return endpoints_.count(endpoint) > 0; }

std::vector<GuidPrefix_t> MatchedEndpoints::participants() const {
  std::vector<GuidPrefix_t> out;
  for (const GUID_t& endpoint : endpoints_) {
    if (out.empty() || out.back() != endpoint.guidPrefix) out.push_back(endpoint.guidPrefix);
  }
  return out;
}

}  // namespace drover::dds::detail

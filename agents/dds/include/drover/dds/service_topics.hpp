#pragma once
// Naming of request/reply services: service <service> of area <area> uses the topics
// drover/<area>/<service>/request and drover/<area>/<service>/reply.

#include <string>
#include <string_view>

#include "drover/common/result.hpp"

namespace drover::dds {

struct ServiceTopics {
  std::string name;     ///< drover/<area>/<service>
  std::string request;  ///< drover/<area>/<service>/request
  std::string reply;    ///< drover/<area>/<service>/reply
};

/// \return the topics of a service, or invalid_argument when area or service is empty or
///         has a character outside [a-z0-9_].
Result<ServiceTopics> service_topics(std::string_view area, std::string_view service);

}  // namespace drover::dds

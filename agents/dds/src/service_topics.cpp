#include "drover/dds/service_topics.hpp"

namespace drover::dds {
namespace {

Status validate_part(std::string_view what, std::string_view part) {
  if (part.empty()) return fail(ErrorCode::invalid_argument, "service " + std::string(what) + " is empty");
  for (char c : part) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) {
      return fail(ErrorCode::invalid_argument, "service " + std::string(what) + " '" +
                                                   std::string(part) + "' has character '" +
                                                   std::string(1, c) + "' (allowed: a-z 0-9 _)");
    }
  }
  return {};
}

}  // namespace

Result<ServiceTopics> service_topics(std::string_view area, std::string_view service) {
  if (auto ok = validate_part("area", area); !ok) return unexpected(ok.error());
  if (auto ok = validate_part("name", service); !ok) return unexpected(ok.error());
  const std::string name = "drover/" + std::string(area) + "/" + std::string(service);
  return ServiceTopics{name, name + "/request", name + "/reply"};
}

}  // namespace drover::dds

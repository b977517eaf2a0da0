#include "drover/dds/detail/requester_filter.hpp"

#include <cstring>
#include <string>

#include <fastdds/dds/topic/IContentFilter.hpp>

namespace drover::dds::detail {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"  // see requester_filter.hpp

class RequesterFilter final : public fdds::IContentFilter {
 public:
  explicit RequesterFilter(std::string requester) : requester_(std::move(requester)) {}

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo&, const GUID_t&) const override {
    return first_string_equals(payload.data, payload.length, requester_);
  }
  void set_requester(std::string requester) { requester_ = std::move(requester); }

 private:
  std::string requester_;
};

#pragma GCC diagnostic pop

}  // namespace

bool first_string_equals(const unsigned char* data, std::uint32_t length, const std::string& requester) {
  // 4 bytes of encapsulation (byte 1: 0x01 little-endian CDR, 0x00 big-endian), then the
  // string: a 4-byte length that counts the terminating NUL, the characters, the NUL.
  constexpr std::uint32_t kHeader = 4;
  if (data == nullptr || length < kHeader + 4) return false;
  const bool little_endian = (data[1] & 0x01) != 0;
  const unsigned char* size_bytes = data + kHeader;
  const std::uint32_t size =
      little_endian ? (std::uint32_t{size_bytes[0]} | std::uint32_t{size_bytes[1]} << 8 |
                       std::uint32_t{size_bytes[2]} << 16 | std::uint32_t{size_bytes[3]} << 24)
                    : (std::uint32_t{size_bytes[3]} | std::uint32_t{size_bytes[2]} << 8 |
                       std::uint32_t{size_bytes[1]} << 16 | std::uint32_t{size_bytes[0]} << 24);
  if (size != requester.size() + 1 || length - kHeader - 4 < size) return false;
  return std::memcmp(size_bytes + 4, requester.data(), requester.size()) == 0;
}

ReturnCode_t RequesterFilterFactory::create_content_filter(const char*, const char*,
                                                           const fdds::TopicDataType*,
                                                           const char* filter_expression,
                                                           const ParameterSeq& filter_parameters,
                                                           fdds::IContentFilter*& filter_instance) {
  if (filter_parameters.length() != 1 || filter_parameters[0] == nullptr) {
    return ReturnCode_t::RETCODE_BAD_PARAMETER;
  }
  if (filter_expression == nullptr) {  // a parameter update of an existing filter
    if (filter_instance == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    static_cast<RequesterFilter*>(filter_instance)->set_requester(filter_parameters[0]);
    return ReturnCode_t::RETCODE_OK;
  }
  if (std::strcmp(filter_expression, kRequesterFilterExpression) != 0) {
    return ReturnCode_t::RETCODE_BAD_PARAMETER;
  }
  delete static_cast<RequesterFilter*>(filter_instance);
  filter_instance = new RequesterFilter(filter_parameters[0]);
  return ReturnCode_t::RETCODE_OK;
}

ReturnCode_t RequesterFilterFactory::delete_content_filter(const char*, fdds::IContentFilter* filter_instance) {
  delete static_cast<RequesterFilter*>(filter_instance);
  return ReturnCode_t::RETCODE_OK;
}

RequesterFilterFactory& RequesterFilterFactory::instance() {
  static RequesterFilterFactory factory;
  return factory;
}

}  // namespace drover::dds::detail

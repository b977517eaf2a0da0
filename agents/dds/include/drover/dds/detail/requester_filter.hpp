#pragma once
// A content filter class for reply topics: keeps the samples whose header.requester equals
// the parameter. Fast DDS's default SQL filter evaluates through DynamicData, which costs
// about 200 us per reply here; this one reads the serialized string in place. Every
// Participant registers it; readers evaluate it on their side (writer_qos() turns
// writer-side filtering off).

#include <cstdint>
#include <string>

#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace drover::dds::detail {

/// The filter class name passed to create_contentfilteredtopic.
inline constexpr const char* kRequesterFilterClass = "DROVER_REQUESTER";
/// The only expression the class accepts; its parameter is the agent id, unquoted.
inline constexpr const char* kRequesterFilterExpression = "header.requester = %0";

// Fast DDS's filter interfaces have no virtual destructor; instances are only ever deleted
// through their own type.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"

/// Stateless: one instance serves every participant of the process.
class RequesterFilterFactory final : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  ReturnCode_t create_content_filter(const char* filter_class_name, const char* type_name,
                                     const eprosima::fastdds::dds::TopicDataType* data_type,
                                     const char* filter_expression,
                                     const ParameterSeq& filter_parameters,
                                     eprosima::fastdds::dds::IContentFilter*& filter_instance) override;
  ReturnCode_t delete_content_filter(const char* filter_class_name,
                                     eprosima::fastdds::dds::IContentFilter* filter_instance) override;

  static RequesterFilterFactory& instance();
};

#pragma GCC diagnostic pop

/// Whether a serialized sample (CDR, as fastddsgen 2.3 writes it) starts with the string
/// `requester`: the first member of every request and reply is RequestHeader, whose first
/// member is the requester. Exposed for tests.
bool first_string_equals(const unsigned char* data, std::uint32_t length, const std::string& requester);

}  // namespace drover::dds::detail

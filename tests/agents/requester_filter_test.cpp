// The reply filter reads header.requester straight from the serialized sample.

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diagnosticsPubSubTypes.h"
#include "drover/dds/detail/requester_filter.hpp"

namespace drover::test {
namespace {

using dds::detail::first_string_equals;

eprosima::fastrtps::rtps::SerializedPayload_t serialize(const std::string& requester) {
  msg::PingReply reply;
  reply.header().requester(requester);
  reply.header().responder("server-1");
  reply.text("some text");
  reply.payload(std::vector<std::uint8_t>(100, 7));
  msg::PingReplyPubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&reply)());
  EXPECT_TRUE(type.serialize(&reply, &payload));
  return payload;
}

TEST(RequesterFilterTest, MatchesTheRequesterOfARealSerializedReply) {
  const auto payload = serialize("client-1");
  EXPECT_TRUE(first_string_equals(payload.data, payload.length, "client-1"));
  EXPECT_FALSE(first_string_equals(payload.data, payload.length, "client-2"));
  EXPECT_FALSE(first_string_equals(payload.data, payload.length, "client"));    // a prefix
  EXPECT_FALSE(first_string_equals(payload.data, payload.length, "client-10"));  // longer
  EXPECT_FALSE(first_string_equals(payload.data, payload.length, "server-1"));  // the responder
}

TEST(RequesterFilterTest, RejectsTruncatedPayloadsAndReadsBigEndian) {
  const auto payload = serialize("client-1");
  EXPECT_FALSE(first_string_equals(payload.data, 10, "client-1"));  // cut inside the string
  EXPECT_FALSE(first_string_equals(payload.data, 4, "client-1"));
  EXPECT_FALSE(first_string_equals(nullptr, 0, "client-1"));

  // Big-endian CDR (encapsulation 0x0000) holding the string "ab": length 3 with its NUL.
  const std::vector<unsigned char> big_endian{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 'a', 'b', 0x00};
  EXPECT_TRUE(first_string_equals(big_endian.data(), static_cast<std::uint32_t>(big_endian.size()), "ab"));
  EXPECT_FALSE(first_string_equals(big_endian.data(), static_cast<std::uint32_t>(big_endian.size()), "ba"));
}

}  // namespace
}  // namespace drover::test

// State and event topics, content filters and participant options, within one process
// (two participants, so everything still goes through discovery and matching).

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drover/dds/reader.hpp"
#include "drover/dds/writer.hpp"
#include "tests/agents/dds_test_support.hpp"
#include "topology.h"

namespace drover::test {
namespace {

/// Samples received by a reader callback, with a condition to wait on.
template <class T>
class Inbox {
 public:
  void push(const T& sample) {
    {
      std::lock_guard lock(mutex_);
      samples_.push_back(sample);
    }
    changed_.notify_all();
  }
  bool wait_for_count(std::size_t count) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDiscoveryTimeout, [&] { return samples_.size() >= count; });
  }
  std::vector<T> samples() {
    std::lock_guard lock(mutex_);
    return samples_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<T> samples_;
};

msg::TimelineState timeline(const std::string& entity, unsigned long long version) {
  msg::TimelineState state;
  state.entity(entity);
  state.version(version);
  return state;
}

TEST(TopicTest, LateJoinerGetsTheLastStateOfEveryInstance) {
  constexpr std::uint32_t kDomain = 30;
  auto publisher = make_participant(kDomain, "publisher");
  auto subscriber = make_participant(kDomain, "subscriber");
  ASSERT_NE(publisher, nullptr);
  ASSERT_NE(subscriber, nullptr);

  auto writer = dds::Writer<msg::TimelineState>::create(*publisher, "drover/test/timeline");
  ASSERT_TRUE(writer.has_value()) << writer.error().message;
  for (auto [entity, version] : std::vector<std::pair<std::string, unsigned long long>>{
           {"e1", 1}, {"e2", 1}, {"e1", 2}, {"e1", 3}}) {
    ASSERT_TRUE((*writer)->write(timeline(entity, version)).has_value());
  }

  Inbox<msg::TimelineState> inbox;
  auto reader = dds::Reader<msg::TimelineState>::create(
      *subscriber, "drover/test/timeline", [&](const msg::TimelineState& s) { inbox.push(s); });
  ASSERT_TRUE(reader.has_value()) << reader.error().message;
  ASSERT_TRUE(inbox.wait_for_count(2));

  // KEEP_LAST 1 per key: e1's history collapsed to its last version.
  std::map<std::string, unsigned long long> versions;
  for (const auto& s : inbox.samples()) versions[s.entity()] = s.version();
  EXPECT_EQ(versions, (std::map<std::string, unsigned long long>{{"e1", 3}, {"e2", 1}}));

  ASSERT_TRUE((*writer)->write(timeline("e2", 2)).has_value());
  ASSERT_TRUE(inbox.wait_for_count(3));
  EXPECT_EQ(inbox.samples().back().version(), 2u);
  EXPECT_EQ(inbox.samples().size(), 3u);
}

TEST(TopicTest, ARetiredInstanceIsNoLongerGivenToLateJoiners) {
  constexpr std::uint32_t kDomain = 38;
  auto publisher = make_participant(kDomain, "publisher");
  auto subscriber = make_participant(kDomain, "subscriber");
  ASSERT_NE(publisher, nullptr);
  ASSERT_NE(subscriber, nullptr);

  auto writer = dds::Writer<msg::TimelineState>::create(*publisher, "drover/test/retired");
  ASSERT_TRUE(writer.has_value()) << writer.error().message;
  for (const char* entity : {"e1", "e2", "e3"}) ASSERT_TRUE((*writer)->write(timeline(entity, 1)).has_value());
  ASSERT_TRUE((*writer)->retire(timeline("e1", 0)).has_value()) << "only the key is read";
  const auto again = (*writer)->retire(timeline("e1", 0));
  ASSERT_FALSE(again.has_value()) << "retired already";
  EXPECT_EQ(again.error().code, ErrorCode::not_found);
  const auto unknown = (*writer)->retire(timeline("e9", 0));
  ASSERT_FALSE(unknown.has_value()) << "never written";
  EXPECT_EQ(unknown.error().code, ErrorCode::not_found);
  // A retired key may be written again: a new instance.
  ASSERT_TRUE((*writer)->write(timeline("e4", 1)).has_value());

  Inbox<msg::TimelineState> inbox;
  auto reader = dds::Reader<msg::TimelineState>::create(
      *subscriber, "drover/test/retired", [&](const msg::TimelineState& s) { inbox.push(s); });
  ASSERT_TRUE(reader.has_value()) << reader.error().message;
  ASSERT_TRUE(inbox.wait_for_count(3));
  // A reliable reader gets a writer's samples in writing order (across instances it may
  // hand them out in any order): had e1 been kept, it would be here before e5.
  ASSERT_TRUE((*writer)->write(timeline("e5", 1)).has_value());
  ASSERT_TRUE(inbox.wait_for_count(4));
  std::set<std::string> entities;
  for (const auto& s : inbox.samples()) entities.insert(s.entity());
  EXPECT_EQ(entities, (std::set<std::string>{"e2", "e3", "e4", "e5"}));
  EXPECT_EQ(inbox.samples().size(), 4u);
}

TEST(TopicTest, FilteredEventReaderGetsOnlyItsAgentsNoticesAllOfThem) {
  constexpr std::uint32_t kDomain = 31;
  auto publisher = make_participant(kDomain, "notifier");
  auto subscriber = make_participant(kDomain, "vehicle-7");
  ASSERT_NE(publisher, nullptr);
  ASSERT_NE(subscriber, nullptr);

  Inbox<msg::ReservationNotice> inbox;
  dds::ReaderOptions options;
  options.qos = dds::TopicQos::events();
  options.filter_expression = "agent = %0";
  options.filter_parameters = {"'vehicle-7'"};
  auto reader = dds::Reader<msg::ReservationNotice>::create(
      *subscriber, "drover/test/notices", [&](const msg::ReservationNotice& n) { inbox.push(n); }, options);
  ASSERT_TRUE(reader.has_value()) << reader.error().message;
  auto writer = dds::Writer<msg::ReservationNotice>::create(*publisher, "drover/test/notices",
                                                             dds::TopicQos::events());
  ASSERT_TRUE(writer.has_value()) << writer.error().message;
  ASSERT_TRUE((*writer)->wait_for_readers(1, kDiscoveryTimeout));

  constexpr int kNotices = 50;  // a burst: KEEP_ALL loses none
  for (int i = 0; i < kNotices; ++i) {
    msg::ReservationNotice notice;
    notice.agent(i % 2 == 0 ? "vehicle-7" : "vehicle-8");
    notice.route(static_cast<unsigned long long>(i));
    ASSERT_TRUE((*writer)->write(notice).has_value());
  }
  ASSERT_TRUE(inbox.wait_for_count(kNotices / 2));
  const auto notices = inbox.samples();
  ASSERT_EQ(notices.size(), static_cast<std::size_t>(kNotices / 2));
  for (std::size_t i = 0; i < notices.size(); ++i) {
    EXPECT_EQ(notices[i].agent(), "vehicle-7");
    EXPECT_EQ(notices[i].route(), 2 * i);  // in order, none lost
  }
}

TEST(TopicTest, OneTopicNameCarriesOneType) {
  auto participant = make_participant(132, "typed");
  ASSERT_NE(participant, nullptr);
  auto first = dds::Writer<msg::TimelineState>::create(*participant, "drover/test/mixed");
  ASSERT_TRUE(first.has_value());
  auto second = dds::Writer<msg::ReservationNotice>::create(*participant, "drover/test/mixed");
  ASSERT_FALSE(second.has_value());
  EXPECT_EQ(second.error().code, ErrorCode::conflict);
  EXPECT_NE(second.error().message.find("drover/test/mixed"), std::string::npos);
}

// Fast DDS 2.9's writer-side filtering races a departed reader's filter removal and
// crashed writers (see writer_qos()); readers filter for themselves instead.
TEST(QosTest, WritersLeaveContentFilteringToTheirReaders) {
  for (const auto& qos : {dds::TopicQos::state(), dds::TopicQos::events(), dds::TopicQos::service()}) {
    EXPECT_EQ(dds::writer_qos(qos).writer_resource_limits().reader_filters_allocation.maximum, 0u);
  }
}

std::string write_temp_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(ParticipantTest, TakesTransportsFromANamedXmlProfile) {
  constexpr std::uint32_t kDomain = 34;
  const std::string profiles = write_temp_file("drover_udp_only.xml", R"(<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor>
      <transport_id>drover_test_udp</transport_id>
      <type>UDPv4</type>
    </transport_descriptor>
  </transport_descriptors>
  <participant profile_name="drover_udp_only">
    <rtps>
      <userTransports><transport_id>drover_test_udp</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
    </rtps>
  </participant>
</profiles>
)");
  dds::ParticipantOptions options;
  options.domain_id = kDomain;
  options.xml_profile_file = profiles;
  options.profile_name = "drover_udp_only";
  options.agent_id = "udp-writer";
  auto writer_side = dds::Participant::create(options);
  ASSERT_TRUE(writer_side.has_value()) << writer_side.error().message;
  options.agent_id = "udp-reader";
  auto reader_side = dds::Participant::create(options);
  ASSERT_TRUE(reader_side.has_value()) << reader_side.error().message;
  EXPECT_FALSE((*writer_side)->native().get_qos().transport().use_builtin_transports);
  EXPECT_EQ((*writer_side)->native().get_qos().name().to_string(), "udp-writer");

  auto writer = dds::Writer<msg::TimelineState>::create(**writer_side, "drover/test/udp");
  ASSERT_TRUE(writer.has_value());
  ASSERT_TRUE((*writer)->write(timeline("e9", 4)).has_value());
  Inbox<msg::TimelineState> inbox;
  auto reader = dds::Reader<msg::TimelineState>::create(**reader_side, "drover/test/udp",
                                                        [&](const msg::TimelineState& s) { inbox.push(s); });
  ASSERT_TRUE(reader.has_value());
  ASSERT_TRUE(inbox.wait_for_count(1));
  EXPECT_EQ(inbox.samples().front().version(), 4u);

  options.profile_name = "no_such_profile";
  auto unknown = dds::Participant::create(options);
  ASSERT_FALSE(unknown.has_value());
  EXPECT_EQ(unknown.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(unknown.error().message.find("no_such_profile"), std::string::npos);

  options.profile_name.clear();
  options.xml_profile_file = write_temp_file("drover_broken.xml", "<profiles><participant");
  auto broken = dds::Participant::create(options);
  ASSERT_FALSE(broken.has_value());
  EXPECT_EQ(broken.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(broken.error().message.find("drover_broken.xml"), std::string::npos) << broken.error().message;
}

TEST(ParticipantTest, RejectsBadAgentIdsAndOptionsWithClearErrors) {
  dds::ParticipantOptions options;
  options.domain_id = 33;
  options.agent_id = "it's me";
  auto bad_id = dds::Participant::create(options);
  ASSERT_FALSE(bad_id.has_value());
  EXPECT_EQ(bad_id.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(bad_id.error().message.find("character '''"), std::string::npos) << bad_id.error().message;

  options.agent_id = "fine";
  options.xml_profile_file = "/nonexistent/profiles.xml";
  auto bad_file = dds::Participant::create(options);
  ASSERT_FALSE(bad_file.has_value());
  EXPECT_NE(bad_file.error().message.find("/nonexistent/profiles.xml"), std::string::npos);

  options.xml_profile_file.clear();
  options.lease_duration = std::chrono::milliseconds(500);
  options.announcement_period = std::chrono::milliseconds(1000);
  auto bad_lease = dds::Participant::create(options);
  ASSERT_FALSE(bad_lease.has_value());
  EXPECT_NE(bad_lease.error().message.find("lease"), std::string::npos);

  options.lease_duration = std::chrono::milliseconds(3000);
  options.domain_id = 300;
  EXPECT_FALSE(dds::Participant::create(options).has_value());
  EXPECT_FALSE(dds::validate_agent_id("").has_value());
  EXPECT_TRUE(dds::validate_agent_id("topology-agent_1.a").has_value());
}

}  // namespace
}  // namespace drover::test

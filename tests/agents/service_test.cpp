// Request/reply over real processes: the test process is the client, dds_test_peer the
// server (drover/diagnostics/ping).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <signal.h>

#include "diagnostics.h"
#include "drover/dds/service_client.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/writer.hpp"
#include "drover/dds/service_topics.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;
using PingClient = dds::ServiceClient<msg::PingRequest, msg::PingReply>;
using PingServer = dds::ServiceServer<msg::PingRequest, msg::PingReply>;

msg::PingRequest ping(const std::string& text, std::vector<uint8_t> payload = {}) {
  msg::PingRequest request;
  request.text(text);
  request.payload(std::move(payload));
  return request;
}

std::unique_ptr<PingClient> make_client(dds::Participant& participant) {
  auto client = PingClient::create(participant, "diagnostics", "ping");
  EXPECT_TRUE(client.has_value()) << (client ? "" : client.error().message);
  return client ? std::move(*client) : nullptr;
}

class ServiceTest : public ::testing::Test {
 protected:
  void start_peer(std::uint32_t domain, const std::string& id) {
    auto peer = spawn_peer(domain, id, {"--echo"});
    ASSERT_TRUE(peer.has_value());
    peers_.push_back(std::move(*peer));
  }
  void TearDown() override { peers_.clear(); }  // kill -9 and reap, whatever happened

  std::vector<ChildProcess> peers_;
};

TEST_F(ServiceTest, ConcurrentClientsEachGetTheirOwnReplies) {
  constexpr std::uint32_t kDomain = 11;
  constexpr int kClients = 3;
  constexpr int kThreadsPerClient = 2;
  constexpr int kCallsPerThread = 20;
  start_peer(kDomain, "echo-server");

  std::vector<std::unique_ptr<dds::Participant>> participants;
  std::vector<std::unique_ptr<PingClient>> clients;
  for (int c = 0; c < kClients; ++c) {
    participants.push_back(make_participant(kDomain, "client-" + std::to_string(c)));
    ASSERT_NE(participants.back(), nullptr);
    clients.push_back(make_client(*participants.back()));
    ASSERT_NE(clients.back(), nullptr);
  }

  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int c = 0; c < kClients; ++c) {
    for (int t = 0; t < kThreadsPerClient; ++t) {
      threads.emplace_back([&, c, t] {
        for (int k = 0; k < kCallsPerThread; ++k) {
          const std::string text = "client-" + std::to_string(c) + "/thread-" + std::to_string(t) +
                                   "/call-" + std::to_string(k);
          const std::vector<uint8_t> payload(static_cast<std::size_t>(16 + k), static_cast<uint8_t>(c * 16 + k));
          auto reply = clients[c]->call(ping(text, payload), kDiscoveryTimeout);
          if (!reply) {
            ADD_FAILURE() << text << ": " << reply.error().message;
            ++failures;
            continue;
          }
          EXPECT_EQ(reply->error().code(), msg::ERROR_NONE) << text;
          EXPECT_EQ(reply->text(), text);
          EXPECT_EQ(reply->payload(), payload) << text;
          EXPECT_EQ(reply->header().requester(), "client-" + std::to_string(c));
          EXPECT_EQ(reply->header().responder(), "echo-server");
        }
      });
    }
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(failures.load(), 0);

  for (int c = 0; c < kClients; ++c) {
    const dds::ClientStats stats = clients[c]->stats();
    EXPECT_EQ(stats.requests_sent, static_cast<std::uint64_t>(kThreadsPerClient * kCallsPerThread));
    // The content filter on the requester id keeps the other clients' replies away.
    EXPECT_EQ(stats.replies_received, stats.requests_sent) << "client " << c;
    EXPECT_EQ(stats.replies_for_other_clients, 0u) << "client " << c;
    EXPECT_EQ(stats.late_replies, 0u) << "client " << c;
  }
  clients.clear();
}

TEST_F(ServiceTest, NoServerIsATimeoutThatSaysNoServerMatched) {
  auto participant = make_participant(17, "lonely-client");
  ASSERT_NE(participant, nullptr);
  auto client = make_client(*participant);
  ASSERT_NE(client, nullptr);

  auto reply = client->call(ping("anyone?"), 300ms);
  ASSERT_FALSE(reply.has_value());
  EXPECT_EQ(reply.error().code, ErrorCode::timeout);
  EXPECT_NE(reply.error().message.find("no server for service 'drover/diagnostics/ping' matched within 300 ms"),
            std::string::npos)
      << reply.error().message;
  EXPECT_EQ(client->stats().requests_sent, 0u);  // nothing is sent into the void
}

TEST_F(ServiceTest, ServerThatDoesNotAnswerIsATimeoutThatNamesIt) {
  constexpr std::uint32_t kDomain = 13;
  start_peer(kDomain, "slow-server");
  auto participant = make_participant(kDomain, "impatient-client");
  ASSERT_NE(participant, nullptr);
  auto client = make_client(*participant);
  ASSERT_NE(client, nullptr);
  ASSERT_TRUE(client->wait_for_server(kDiscoveryTimeout).has_value());

  auto reply = client->call(ping("hold:never"), 500ms);
  ASSERT_FALSE(reply.has_value());
  EXPECT_EQ(reply.error().code, ErrorCode::timeout);
  EXPECT_NE(reply.error().message.find("server 'slow-server' did not reply to 'drover/diagnostics/ping' within 500 ms"),
            std::string::npos)
      << reply.error().message;
  EXPECT_EQ(client->stats().requests_sent, 1u);
}

TEST_F(ServiceTest, DeferredReplyArrivesWhenTheServerCompletesIt) {
  constexpr std::uint32_t kDomain = 14;
  start_peer(kDomain, "deferring-server");
  auto participant = make_participant(kDomain, "patient-client");
  ASSERT_NE(participant, nullptr);
  auto client = make_client(*participant);
  ASSERT_NE(client, nullptr);

  auto held = std::async(std::launch::async, [&] { return client->call(ping("hold:k1"), kDiscoveryTimeout); });

  // The release is refused (not_found) until the held request has reached the server;
  // every attempt is a full round trip, so this loop waits on the server's state.
  const auto deadline = std::chrono::steady_clock::now() + kDiscoveryTimeout;
  bool released = false;
  while (!released && std::chrono::steady_clock::now() < deadline) {
    auto reply = client->call(ping("release:k1"), kDiscoveryTimeout);
    ASSERT_TRUE(reply.has_value()) << reply.error().message;
    if (reply->error().code() == msg::ERROR_NONE) {
      EXPECT_EQ(reply->text(), "released");
      released = true;
    } else {
      ASSERT_EQ(reply->error().code(), msg::ERROR_NOT_FOUND) << reply->error().message();
    }
  }
  ASSERT_TRUE(released);

  auto reply = held.get();
  ASSERT_TRUE(reply.has_value()) << reply.error().message;
  EXPECT_EQ(reply->error().code(), msg::ERROR_NONE);
  EXPECT_EQ(reply->text(), "released k1");
  EXPECT_EQ(reply->header().requester(), "patient-client");
}

TEST_F(ServiceTest, CallFailsWhenItsServerDiesWhileHoldingIt) {
  constexpr std::uint32_t kDomain = 15;
  start_peer(kDomain, "doomed-server");
  auto participant = make_participant(kDomain, "orphaned-client");
  ASSERT_NE(participant, nullptr);
  auto client = make_client(*participant);
  ASSERT_NE(client, nullptr);
  ASSERT_TRUE(client->wait_for_server(kDiscoveryTimeout).has_value());

  auto held = std::async(std::launch::async, [&] { return client->call(ping("hold:forever"), 60s); });
  // The held request must be at the server before it dies; a round trip behind it on the
  // same writer proves that (the server handles requests in order).
  auto behind = client->call(ping("after hold"), kDiscoveryTimeout);
  ASSERT_TRUE(behind.has_value()) << behind.error().message;
  peers_.front().signal(SIGKILL);

  // Participant lease 3 s: the call fails well before its own 60 s timeout.
  ASSERT_EQ(held.wait_for(kDiscoveryTimeout), std::future_status::ready);
  auto reply = held.get();
  ASSERT_FALSE(reply.has_value());
  EXPECT_EQ(reply.error().code, ErrorCode::unavailable);
  EXPECT_NE(reply.error().message.find("server 'doomed-server' of 'drover/diagnostics/ping' went away"),
            std::string::npos)
      << reply.error().message;
}

TEST_F(ServiceTest, RequestsGoToTheNamedServerOrToEachServerInTurn) {
  constexpr std::uint32_t kDomain = 16;
  start_peer(kDomain, "echo-a");
  start_peer(kDomain, "echo-b");
  auto participant = make_participant(kDomain, "choosy-client");
  ASSERT_NE(participant, nullptr);
  auto client = make_client(*participant);
  ASSERT_NE(client, nullptr);
  ASSERT_TRUE(client->wait_for_server(kDiscoveryTimeout, "echo-a").has_value());
  ASSERT_TRUE(client->wait_for_server(kDiscoveryTimeout, "echo-b").has_value());

  for (const std::string server : {"echo-b", "echo-a", "echo-b"}) {
    auto reply = client->call(ping("to " + server), kDiscoveryTimeout, server);
    ASSERT_TRUE(reply.has_value()) << reply.error().message;
    EXPECT_EQ(reply->header().responder(), server);
    EXPECT_EQ(reply->text(), "to " + server);
  }
  std::vector<std::string> responders;
  for (int i = 0; i < 4; ++i) {
    auto reply = client->call(ping("to anyone"), kDiscoveryTimeout);
    ASSERT_TRUE(reply.has_value()) << reply.error().message;
    responders.push_back(reply->header().responder());
  }
  // Every request is answered once, by one server, and both servers take turns.
  EXPECT_EQ(client->stats().replies_received, client->stats().requests_sent);
  EXPECT_NE(std::find(responders.begin(), responders.end(), "echo-a"), responders.end());
  EXPECT_NE(std::find(responders.begin(), responders.end(), "echo-b"), responders.end());

  auto unknown = client->call(ping("to nobody"), 300ms, "echo-c");
  ASSERT_FALSE(unknown.has_value());
  EXPECT_NE(unknown.error().message.find("no server 'echo-c' for service"), std::string::npos)
      << unknown.error().message;
}

// An echo server in the test process that records what each reply's send returned.
class RecordingServer {
 public:
  RecordingServer(dds::Participant& participant, std::chrono::milliseconds reply_match_timeout) {
    auto server = PingServer::create(
        participant, "diagnostics", "ping",
        [this](const msg::PingRequest& request, dds::ReplyHandle<msg::PingReply> handle) {
          msg::PingReply reply;
          reply.text(request.text());
          Status sent = handle.send(std::move(reply));
          std::lock_guard lock(mutex_);
          sends_.emplace_back(request.text(), std::move(sent));
          changed_.notify_all();
        },
        dds::ServerOptions{reply_match_timeout});
    EXPECT_TRUE(server.has_value()) << (server ? "" : server.error().message);
    if (server) server_ = std::move(*server);
  }
  bool ok() const { return server_ != nullptr; }

  /// The outcome of sending the reply to the request with text `text`, once known.
  std::optional<Status> send_outcome(const std::string& text) {
    std::unique_lock lock(mutex_);
    std::optional<Status> found;
    changed_.wait_for(lock, kDiscoveryTimeout, [&] {
      for (const auto& [sent_text, status] : sends_) {
        if (sent_text == text) found = status;
      }
      return found.has_value();
    });
    return found;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::pair<std::string, Status>> sends_;
  std::unique_ptr<PingServer> server_;  // last: its handler stops before the rest goes
};

// One agent may have several clients of one service (a RAN client per vehicle, say). A
// reply must wait for the reply reader of the client that asked: were it written once any
// reader of the agent matched, it would be lost to a client whose reader the server has
// not matched yet.
TEST_F(ServiceTest, AReplyWaitsForTheReplyReaderOfTheClientThatAsked) {
  constexpr std::uint32_t kDomain = 19;
  auto server_participant = make_participant(kDomain, "strict-server");
  ASSERT_NE(server_participant, nullptr);
  RecordingServer server(*server_participant, 500ms);
  ASSERT_TRUE(server.ok());

  auto participant = make_participant(kDomain, "many-clients");
  ASSERT_NE(participant, nullptr);
  auto first = make_client(*participant);
  ASSERT_NE(first, nullptr);
  auto answered = first->call(ping("first"), kDiscoveryTimeout);  // its reader is matched now
  ASSERT_TRUE(answered.has_value()) << answered.error().message;
  EXPECT_NE(answered->header().reply_reader(), 0u);  // the SDK names its reply reader

  // A request naming a reply reader that does not exist: another reader of the agent is
  // matched, yet the reply is not written, and its send says why.
  auto raw = dds::Writer<msg::PingRequest>::create(*participant, "drover/diagnostics/ping/request",
                                                    dds::TopicQos::service());
  ASSERT_TRUE(raw.has_value()) << raw.error().message;
  ASSERT_TRUE((*raw)->wait_for_readers(1, kDiscoveryTimeout));
  msg::PingRequest to_nobody = ping("to a reader nobody has");
  to_nobody.header().requester("many-clients");
  to_nobody.header().reply_reader(0x00ffff07);
  ASSERT_TRUE((*raw)->write(to_nobody).has_value());
  auto unsent = server.send_outcome("to a reader nobody has");
  ASSERT_TRUE(unsent.has_value());
  ASSERT_FALSE(unsent->has_value());
  EXPECT_EQ(unsent->error().code, ErrorCode::timeout);
  EXPECT_NE(unsent->error().message.find("its reply reader did not match within 500 ms"), std::string::npos)
      << unsent->error().message;

  // A request that names no reply reader (a client not built on the SDK) is answered once
  // any reader of its agent is matched: the first client gets it and sets it aside.
  msg::PingRequest unnamed = ping("no reader named");
  unnamed.header().requester("many-clients");
  ASSERT_TRUE((*raw)->write(unnamed).has_value());
  auto sent = server.send_outcome("no reader named");
  ASSERT_TRUE(sent.has_value());
  EXPECT_TRUE(sent->has_value()) << sent->error().message;

  // Clients made and used at once, next to the first one, each get their reply.
  for (int k = 0; k < 10; ++k) {
    auto next = make_client(*participant);
    ASSERT_NE(next, nullptr);
    auto reply = next->call(ping("next " + std::to_string(k)), kDiscoveryTimeout);
    ASSERT_TRUE(reply.has_value()) << reply.error().message;
    EXPECT_EQ(reply->text(), "next " + std::to_string(k));
    auto outcome = server.send_outcome("next " + std::to_string(k));
    ASSERT_TRUE(outcome.has_value());
    EXPECT_TRUE(outcome->has_value()) << outcome->error().message;
  }
}

TEST(ServiceTopicsTest, NamesFollowTheConvention) {
  auto topics = dds::service_topics("topology", "reserve_prepare");
  ASSERT_TRUE(topics.has_value());
  EXPECT_EQ(topics->name, "drover/topology/reserve_prepare");
  EXPECT_EQ(topics->request, "drover/topology/reserve_prepare/request");
  EXPECT_EQ(topics->reply, "drover/topology/reserve_prepare/reply");

  auto bad = dds::service_topics("topology", "Reserve/Prepare");
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(bad.error().message.find("'R'"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(dds::service_topics("", "ping").has_value());
}

}  // namespace
}  // namespace drover::test

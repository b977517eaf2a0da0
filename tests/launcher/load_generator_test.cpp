// The load generator against order servers in this process (domains 29 and 57, one per
// test: ctest runs them side by side), standing in for the logical agents: which vehicles it
// sends orders to, and what a refusal changes.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drover/dds/participant.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/writer.hpp"
#include "drover/launcher/load_generator.hpp"
#include "drover/logical_agent/messages.hpp"
#include "drover/logical_agent/names.hpp"
#include "tests/agents/dds_test_support.hpp"

namespace drover::test {
namespace {

using namespace std::chrono_literals;
using OrderServer = dds::ServiceServer<msg::OrderRequest, msg::OrderReply>;

constexpr auto kTimeout = 60s;

/// The order requests each vehicle's server received, in order.
struct Received {
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, std::vector<msg::OrderRequest>> requests;

  bool wait(const std::function<bool()>& condition) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, kTimeout, condition);
  }
  std::size_t count(const std::string& vehicle) { return requests[vehicle].size(); }
};

/// Vehicle `id`'s order service: refuses every order with `refusal` when given, else queues it.
std::unique_ptr<OrderServer> order_server(dds::Participant& vehicle, Received& received,
                                          std::optional<Error> refusal) {
  auto server = OrderServer::create(
      vehicle, logical_agent::kServiceArea, logical_agent::kOrderService,
      [&received, refusal, id = vehicle.agent_id()](const msg::OrderRequest& request,
                                                     dds::ReplyHandle<msg::OrderReply> reply) {
        {
          std::lock_guard lock(received.mutex);
          received.requests[id].push_back(request);
        }
        received.changed.notify_all();
        if (refusal) {
          (void)reply.send_error(*refusal);
        } else {
          msg::OrderReply queued;
          queued.queue_position(1);
          (void)reply.send(std::move(queued));
        }
      });
  EXPECT_TRUE(server.has_value()) << (server ? "" : server.error().message);
  return server ? std::move(*server) : nullptr;
}

/// Polls the generator's figures (counted once a reply is taken in) until `condition` holds.
bool wait_figures(const launcher::LoadGenerator& generator,
                  const std::function<bool(const launcher::LoadFigures&)>& condition) {
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  while (!condition(generator.figures())) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

msg::VehicleState idle(const std::string& vehicle, std::int64_t time) {
  msg::VehicleState state;
  state.vehicle(vehicle);
  state.state(msg::VEHICLE_IDLE);
  state.time().ns(time);
  return state;
}

/// The generator under test on its own participant, and a writer of vehicle states (on
/// `vehicles`) that its reader has matched. Members go in reverse: the generator before its
/// participant.
struct GeneratorRun {
  std::unique_ptr<dds::Writer<msg::VehicleState>> states;
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<launcher::LoadGenerator> generator;
};

void start_generator(std::uint32_t domain, dds::Participant& vehicles, GeneratorRun& run) {
  auto states = dds::Writer<msg::VehicleState>::create(vehicles, logical_agent::kVehicleStateTopic);
  ASSERT_TRUE(states.has_value()) << states.error().message;
  run.states = std::move(*states);
  run.participant = make_participant(domain, "load-generator");
  ASSERT_TRUE(run.participant);
  launcher::LoadGeneratorOptions options;
  options.stations = {"a", "b"};
  options.request_timeout = kTimeout;
  auto generator = launcher::LoadGenerator::create(*run.participant, options);
  ASSERT_TRUE(generator.has_value()) << generator.error().message;
  run.generator = std::move(*generator);
  ASSERT_TRUE(run.states->wait_for_readers(1, kTimeout)) << "the generator's vehicle reader never matched";
}

TEST(LoadGenerator, AVehicleThatRefusesAnOrderAsInvalidGetsNoMoreWhileTheOthersDo) {
  constexpr std::uint32_t kDomain = 29;
  Received received;
  auto v1 = make_participant(kDomain, "V1");
  auto v2 = make_participant(kDomain, "V2");
  ASSERT_TRUE(v1 && v2);
  // V1's RAN does not load: its logical agent refuses every order the generator sends.
  auto refusing = order_server(*v1, received, Error{ErrorCode::invalid_argument,
                                                    "vehicle 'V1' does not perform 'load' (its RAN performs: charge)"});
  auto accepting = order_server(*v2, received, std::nullopt);
  ASSERT_TRUE(refusing && accepting);
  GeneratorRun run;
  ASSERT_NO_FATAL_FAILURE(start_generator(kDomain, *v1, run));
  auto& states = run.states;
  auto& generator = run.generator;

  ASSERT_TRUE(states->write(idle("V1", 1)).has_value());
  ASSERT_TRUE(received.wait([&] { return received.count("V1") == 1; })) << "V1 got no order";
  {
    std::lock_guard lock(received.mutex);
    const auto& first = received.requests["V1"].front();
    ASSERT_EQ(first.destinations().size(), 2u);
    EXPECT_EQ(first.destinations()[0].operation(), "load");
    EXPECT_EQ(first.destinations()[1].operation(), "unload");
  }
  ASSERT_TRUE(wait_figures(*generator, [](const auto& f) { return f.refused == 1; }));
  // V1 idle again, then V2 idle: the generator handles the states in order, so by the time
  // V2's order arrives it has decided on V1's second state (before, a second order went to
  // V1, and another at each of its state reports).
  ASSERT_TRUE(states->write(idle("V1", 2)).has_value());
  ASSERT_TRUE(states->write(idle("V2", 3)).has_value());
  ASSERT_TRUE(received.wait([&] { return received.count("V2") == 1; })) << "V2 got no order";
  {
    std::lock_guard lock(received.mutex);
    EXPECT_EQ(received.count("V1"), 1u) << "V1 was sent another order after refusing one as invalid";
  }
  ASSERT_TRUE(wait_figures(*generator, [](const auto& f) { return f.queued == 1; }));
  const auto figures = generator->figures();
  EXPECT_EQ(figures.queued, 1u);
  EXPECT_EQ(figures.refused, 1u);
  EXPECT_EQ(figures.left_out, 1u);
}

TEST(LoadGenerator, AVehicleThatRefusesForAnotherReasonIsTriedAgain) {
  constexpr std::uint32_t kDomain = 57;
  Received received;
  auto v1 = make_participant(kDomain, "V1");
  ASSERT_TRUE(v1);
  // Not for what the order asks (its journal failed, say): the next order may be taken.
  auto refusing = order_server(*v1, received, Error{ErrorCode::unavailable, "the order journal cannot be written"});
  ASSERT_TRUE(refusing);
  GeneratorRun run;
  ASSERT_NO_FATAL_FAILURE(start_generator(kDomain, *v1, run));
  auto& states = run.states;
  auto& generator = run.generator;

  ASSERT_TRUE(states->write(idle("V1", 1)).has_value());
  ASSERT_TRUE(received.wait([&] { return received.count("V1") == 1; })) << "V1 got no order";
  ASSERT_TRUE(wait_figures(*generator, [](const auto& f) { return f.refused == 1; }));
  ASSERT_TRUE(states->write(idle("V1", 2)).has_value());
  ASSERT_TRUE(received.wait([&] { return received.count("V1") == 2; })) << "V1 was not tried again";
  const auto figures = generator->figures();
  EXPECT_EQ(figures.left_out, 0u);
}

}  // namespace
}  // namespace drover::test

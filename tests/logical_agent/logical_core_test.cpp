// The logical agent's logic without DDS: order queue, route tracking (allocation look-ahead,
// moves only onto allocated steps, delays, lateness), footprint monitoring and release,
// travel-time estimates, vehicle profile files. On the bundled H-shaped crossing.

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <boost/geometry.hpp>
#include <gtest/gtest.h>

#include "agents/logical_agent/src/command_watch.hpp"
#include "agents/logical_agent/src/footprint_monitor.hpp"
#include "agents/logical_agent/src/late_grants.hpp"
#include "agents/logical_agent/src/order_book.hpp"
#include "agents/logical_agent/src/route_tracker.hpp"
#include "agents/logical_agent/src/travel_time.hpp"
#include "drover/carp/vehicle_profile_json.hpp"
#include "drover/ran/motion_area.hpp"
#include "drover/ran/status.hpp"
#include "drover/topology/topology_file.hpp"

namespace drover::logical_agent {
namespace {

std::shared_ptr<const topology::Topology> h_crossing() {
  const char* source = std::getenv("DROVER_SOURCE_DIR");
  const std::string path = std::string(source ? source : ".") + "/launch/topologies/h_crossing.json";
  auto loaded = topology::load_topology_file(path);
  if (!loaded) throw std::runtime_error("cannot load " + path);
  return std::make_shared<const topology::Topology>(std::move(*loaded));
}

topology::EntityIndex index(const topology::Topology& world, const std::string& id) {
  auto found = world.find(id);
  if (!found) throw std::runtime_error("no entity " + id);
  return *found;
}

/// left-0 -> left-1 -> left-2 -> bar-1, one second per metre, 1 s clearance.
RouteTracker left_route(const std::shared_ptr<const topology::Topology>& world) {
  const std::vector<std::string> ids = {"left-0", "left-0<->left-1", "left-1", "left-1<->left-2",
                                        "left-2", "left-2<->bar-1",  "bar-1"};
  std::vector<topology::RouteStep> steps;
  TimeNs t = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const auto entity = index(*world, ids[i]);
    const bool vertex = i % 2 == 0;
    const DurationNs stay = vertex ? 0 : seconds_to_ns(world->edge(entity).length);
    const TimeNs end = i + 1 == ids.size() ? kForever : t + stay + seconds_to_ns(1);
    steps.push_back(topology::RouteStep{entity, {t, end}});
    t += stay;
  }
  return RouteTracker(world, 42, std::move(steps));
}

ran::VehicleStatus status_at(double x, double y, double theta = 0) {
  ran::VehicleStatus status;
  status.pose = {x, y, theta};
  topology::Polygon shape;
  for (auto [px, py] : {std::pair{-0.3, -0.2}, {-0.3, 0.2}, {0.3, 0.2}, {0.3, -0.2}, {-0.3, -0.2}}) {
    shape.outer().emplace_back(px, py);
  }
  status.footprint = ran::footprint_at(shape, status.pose);
  return status;
}

// ---- orders ----

TEST(OrderBook, ValidatesLocationsAgainstTheTopology) {
  const auto world = h_crossing();
  auto bad = make_order(*world, OrderSpec{"o1", {{"left-4", "load", {}}, {"nowhere", "unload", {}}}, {}});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(bad.error().message.find("destination 1: 'nowhere'"), std::string::npos) << bad.error().message;
  auto edge = make_order(*world, OrderSpec{"o2", {{"left-0<->left-1", "NOP", {}}}, {}});
  ASSERT_FALSE(edge);
  EXPECT_FALSE(make_order(*world, OrderSpec{"o3", {}, {}}));
  EXPECT_FALSE(make_order(*world, OrderSpec{"", {{"left-4", "", {}}}, {}}));
}

// The name is the key of the order's progress on DDS: a name that cannot be published
// must be refused before the order is queued or journaled, not when it starts.
TEST(OrderBook, RefusesNamesThatCannotTravelAsDdsKeys) {
  const auto world = h_crossing();
  EXPECT_TRUE(make_order(*world, OrderSpec{std::string(255, 'n'), {{"left-4", "NOP", {}}}, {}}));
  auto too_long = make_order(*world, OrderSpec{std::string(256, 'n'), {{"left-4", "NOP", {}}}, {}});
  ASSERT_FALSE(too_long);
  EXPECT_EQ(too_long.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(too_long.error().message.find("order name 'nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn...' is 256 bytes long"),
            std::string::npos)
      << too_long.error().message;
  auto with_newline = make_order(*world, OrderSpec{"two\nlines", {{"left-4", "NOP", {}}}, {}});
  ASSERT_FALSE(with_newline);
  EXPECT_NE(with_newline.error().message.find("'two\\x0alines' contains the control character 0x0a at byte 3"),
            std::string::npos)
      << with_newline.error().message;
}

TEST(OrderBook, RunsOrdersInArrivalOrderThroughEveryDestination) {
  const auto world = h_crossing();
  std::vector<std::string> seen;
  OrderBook book({.changed = [&](const Order& order) {
    seen.push_back(order.name + ":" + to_string(order.state) + ":" + std::to_string(order.destination));
  }});
  auto first = make_order(*world, OrderSpec{"a", {{"left-4", "load", {}}, {"right-4", "unload", {}}}, {}});
  auto second = make_order(*world, OrderSpec{"b", {{"left-0", "park", {}}}, {}});
  ASSERT_TRUE(first && second);
  EXPECT_EQ(book.add(*first, 10).value(), 1u);
  EXPECT_EQ(book.add(*second, 11).value(), 2u);
  auto duplicate = book.add(*first, 12);
  ASSERT_FALSE(duplicate);
  EXPECT_EQ(duplicate.error().code, ErrorCode::conflict);

  const Order* running = book.start_next(20);
  ASSERT_NE(running, nullptr);
  EXPECT_EQ(running->name, "a");
  EXPECT_EQ(book.start_next(21)->name, "a") << "one order at a time";
  EXPECT_EQ(book.queued_count(), 1u);
  EXPECT_TRUE(book.advance(30));
  EXPECT_FALSE(book.advance(40));
  EXPECT_EQ(book.find("a")->state, OrderState::finished);
  EXPECT_EQ(book.find("a")->started, 20);
  EXPECT_EQ(book.find("a")->finished, 40);
  EXPECT_EQ(book.start_next(50)->name, "b");
  book.fail_current("stalled too long", 60);
  EXPECT_EQ(book.find("b")->state, OrderState::failed);
  EXPECT_EQ(book.find("b")->failure, "stalled too long");
  EXPECT_EQ(book.start_next(70), nullptr);
  EXPECT_EQ(seen, (std::vector<std::string>{"a:queued:0", "b:queued:0", "a:running:0", "a:running:1",
                                            "a:finished:2", "b:running:0", "b:failed:0"}));
}

TEST(OrderBook, WithdrawsAQueuedOrderAtOnceAndARunningOneWhenTheExecutorEndsIt) {
  const auto world = h_crossing();
  std::vector<std::string> seen;
  OrderBook book({.changed = [&](const Order& order) {
    seen.push_back(order.name + ":" + to_string(order.state) + ":" + order.failure);
  }});
  for (const char* name : {"a", "b", "c"}) {
    auto order = make_order(*world, OrderSpec{name, {{"left-4", "NOP", {}}, {"right-4", "NOP", {}}}, {}});
    ASSERT_TRUE(order);
    ASSERT_TRUE(book.add(*order, 10));
  }
  ASSERT_EQ(book.start_next(20)->name, "a");

  // Queued: withdrawn at once, never started.
  EXPECT_EQ(book.withdraw("b", "wrong pallet", 30).value(), OrderState::withdrawn);
  EXPECT_EQ(book.find("b")->finished, 30);
  EXPECT_FALSE(book.find("b")->started);
  EXPECT_EQ(book.queued_count(), 1u);
  // Running: only marked; the first reason stays.
  EXPECT_FALSE(book.withdrawal_pending());
  EXPECT_EQ(book.withdraw("a", "line stopped", 40).value(), OrderState::running);
  EXPECT_EQ(book.withdraw("a", "again", 41).value(), OrderState::running);
  EXPECT_TRUE(book.withdrawal_pending());
  EXPECT_EQ(book.find("a")->state, OrderState::running);
  book.end_withdrawn(50);
  EXPECT_EQ(book.find("a")->state, OrderState::withdrawn);
  EXPECT_EQ(book.find("a")->finished, 50);
  EXPECT_FALSE(book.withdrawal_pending());
  // The next order runs as usual.
  EXPECT_EQ(book.start_next(60)->name, "c");
  EXPECT_FALSE(book.withdrawal_pending());

  // Ended or unknown orders are refused, and nothing changes.
  const auto ended = book.withdraw("a", "late", 70);
  ASSERT_FALSE(ended);
  EXPECT_EQ(ended.error().code, ErrorCode::conflict);
  EXPECT_NE(ended.error().message.find("withdrawn"), std::string::npos) << ended.error().message;
  const auto unknown = book.withdraw("zz", "", 70);
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::not_found);
  EXPECT_EQ(seen, (std::vector<std::string>{"a:queued:", "b:queued:", "c:queued:", "a:running:",
                                            "b:withdrawn:wrong pallet", "a:withdrawn:line stopped",
                                            "c:running:"}));
}

TEST(OrderBook, KeepsTheNewestEndedOrdersOnlyAndAPointerToTheRunningOneStaysValid) {
  const auto world = h_crossing();
  std::vector<std::string> forgotten;
  OrderBook book({.forgotten = [&](const std::string& name) { forgotten.push_back(name); }}, 2);
  const auto add = [&](const char* name) {
    auto order = make_order(*world, OrderSpec{name, {{"left-4", "NOP", {}}}, {}});
    ASSERT_TRUE(order);
    ASSERT_TRUE(book.add(*order, 10));
  };
  for (const char* name : {"a", "b", "c", "d"}) add(name);
  ASSERT_EQ(book.start_next(20)->name, "a");
  EXPECT_FALSE(book.advance(21));  // a finished
  const Order* b = book.start_next(22);
  ASSERT_EQ(b->name, "b");
  // Withdrawn behind the running b: kept until the orders before it are gone.
  ASSERT_TRUE(book.withdraw("d", "not needed", 23));
  ASSERT_TRUE(book.withdraw("c", "not needed", 24));
  // Three ended (a, c, d), two kept: a, the oldest, is forgotten, b's pointer still holds.
  EXPECT_EQ(book.find("a"), nullptr);
  EXPECT_EQ(forgotten, std::vector<std::string>{"a"}) << "what was published of it can go";
  EXPECT_EQ(book.current(), b);
  EXPECT_EQ(b->name, "b");
  ASSERT_NE(book.find("c"), nullptr);
  // A forgotten name may come again; a kept one may not.
  add("a");
  auto again = make_order(*world, OrderSpec{"c", {{"left-4", "NOP", {}}}, {}});
  ASSERT_TRUE(again);
  EXPECT_EQ(book.add(*again, 30).error().code, ErrorCode::conflict);
  EXPECT_FALSE(book.advance(31));  // b finished: b, c and d ended, b (the oldest) goes
  EXPECT_EQ(book.find("b"), nullptr);
  EXPECT_EQ(forgotten, (std::vector<std::string>{"a", "b"}));
  EXPECT_NE(book.find("c"), nullptr);
  EXPECT_NE(book.find("d"), nullptr);
  EXPECT_EQ(book.start_next(32)->name, "a");
}

TEST(OrderBook, AWithdrawnOrderForgottenAtOnceStillAnswersWithdrawn) {
  const auto world = h_crossing();
  std::vector<std::string> events;
  // Keeps no ended order: the withdrawn one goes as it ends, after it was published.
  OrderBook book({.changed = [&](const Order& order) { events.push_back("published " + order.name + ":" + to_string(order.state)); },
                  .forgotten = [&](const std::string& name) { events.push_back("forgotten " + name); }},
                 0);
  for (const char* name : {"a", "b"}) {
    auto order = make_order(*world, OrderSpec{name, {{"left-4", "NOP", {}}}, {}});
    ASSERT_TRUE(order);
    ASSERT_TRUE(book.add(*order, 10));
  }
  EXPECT_EQ(book.withdraw("a", "not needed", 20).value(), OrderState::withdrawn);
  EXPECT_EQ(book.find("a"), nullptr);
  EXPECT_EQ(events, (std::vector<std::string>{"published a:queued", "published b:queued", "published a:withdrawn",
                                              "forgotten a"}));
  EXPECT_EQ(book.start_next(30)->name, "b");
}

TEST(OrderBook, RecordsEveryChangeBeforePublishingAndARecordingFailureRefusesANewOrder) {
  const auto world = h_crossing();
  std::vector<std::string> events;
  bool disk_full = false;
  OrderBook book({.changed = [&](const Order& order) { events.push_back("published " + order.name + ":" + to_string(order.state)); },
                  .record = [&](const Order& order, bool added) -> Status {
                    if (disk_full) return fail(ErrorCode::io, "disk full");
                    events.push_back(std::string(added ? "added " : "recorded ") + order.name + ":" +
                                     to_string(order.state) + ":" + std::to_string(order.destination) + ":" +
                                     order.action_command.value_or("-") + ":" + order.withdrawal.value_or("-"));
                    return {};
                  }});
  auto a = make_order(*world, OrderSpec{"a", {{"left-4", "load", {}}, {"right-4", "unload", {}}}, {}});
  auto b = make_order(*world, OrderSpec{"b", {{"left-0", "NOP", {}}}, {}});
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(book.add(*a, 10));
  ASSERT_EQ(book.start_next(20)->name, "a");
  EXPECT_TRUE(book.action_commanded("c-1"));
  EXPECT_TRUE(book.advance(30));  // the next destination has no action commanded yet
  ASSERT_TRUE(book.withdraw("a", "line stopped", 40));

  disk_full = true;
  const auto refused = book.add(*b, 50);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::io);
  EXPECT_EQ(book.find("b"), nullptr) << "a refused order is not queued";
  EXPECT_EQ(book.queued_count(), 0u);
  // An action that cannot be recorded is told so (the agent does not command it).
  EXPECT_EQ(book.action_commanded("c-2").error().code, ErrorCode::io);
  book.end_withdrawn(60);  // other changes go on, published though not recorded
  EXPECT_EQ(book.find("a")->state, OrderState::withdrawn);

  EXPECT_EQ(events, (std::vector<std::string>{
                        "added a:queued:0:-:-", "published a:queued", "recorded a:running:0:-:-", "published a:running",
                        "recorded a:running:0:c-1:-", "recorded a:running:1:-:-", "published a:running",
                        "recorded a:running:1:-:line stopped", "published a:withdrawn"}));
}

TEST(OrderBook, RestoresWhatAnEarlierLifeStoredAndGoesOnFromThere) {
  const auto world = h_crossing();
  std::vector<std::string> published;
  std::size_t recorded = 0;
  std::size_t forgotten = 0;
  OrderBook book({.changed = [&](const Order& order) { published.push_back(order.name + ":" + to_string(order.state)); },
                  .record = [&](const Order&, bool) -> Status {
                    ++recorded;
                    return {};
                  },
                  .forgotten = [&](const std::string&) { ++forgotten; }},
                 1);
  std::vector<Order> stored;
  for (const char* name : {"old", "older-still", "running", "queued"}) {
    auto order = make_order(*world, OrderSpec{name, {{"left-4", "load", {}}, {"right-4", "NOP", {}}}, {}});
    ASSERT_TRUE(order);
    stored.push_back(*order);
  }
  stored[0].state = OrderState::finished;
  stored[1].state = OrderState::failed;
  stored[2].state = OrderState::running;
  stored[2].destination = 1;
  book.restore(stored);
  EXPECT_EQ(recorded, 0u) << "restored orders are stored already";
  // One ended order kept: the oldest is left out, never published (nothing to retire).
  EXPECT_EQ(published, (std::vector<std::string>{"older-still:failed", "running:running", "queued:queued"}));
  EXPECT_EQ(forgotten, 0u);
  // Names known stay refused.
  EXPECT_EQ(book.find("old"), nullptr);
  ASSERT_NE(book.find("older-still"), nullptr);
  EXPECT_EQ(book.add(stored[3], 5).error().code, ErrorCode::conflict);
  // The running order goes on where it was, then the queue.
  ASSERT_NE(book.current(), nullptr);
  EXPECT_EQ(book.start_next(10)->name, "running");
  EXPECT_EQ(book.current()->destination, 1u);
  EXPECT_FALSE(book.advance(20));
  EXPECT_EQ(book.start_next(30)->name, "queued");
}

TEST(OrderBook, OperationsBecomeRanActions) {
  EXPECT_FALSE(operation_action(Destination{0, "x", "NOP", {}}));
  EXPECT_FALSE(operation_action(Destination{0, "x", "", {}}));
  EXPECT_FALSE(operation_action(Destination{0, "x", "park", {}}));
  EXPECT_EQ(operation_action(Destination{0, "x", "load", {}})->kind, ran::ActionKind::load);
  EXPECT_EQ(operation_action(Destination{0, "x", "charge", {}})->kind, ran::ActionKind::charge);
  auto custom = operation_action(Destination{0, "x", "lift", {{"height", "1.2"}}});
  ASSERT_TRUE(custom);
  EXPECT_EQ(custom->kind, ran::ActionKind::custom);
  EXPECT_EQ(custom->name, "lift");
  EXPECT_EQ(custom->parameters.at("height"), "1.2");
}

TEST(OrderBook, OperationsTheVehicleDoesNotPerformAreRefusedNamingWhatItDoes) {
  const auto world = h_crossing();
  OrderSpec spec{"o", {{"left-0", "NOP", {}}, {"left-4", "load", {}}, {"right-4", "lift", {}}, {"left-0", "park", {}}},
                 {}};
  const auto order = make_order(*world, spec);
  ASSERT_TRUE(order.has_value()) << order.error().message;
  ran::VehicleStatus status;
  status.vehicle_id = "V1";
  EXPECT_TRUE(check_operations(*order, status)) << "nothing advertised: the RAN decides";
  status.actions = {"load", "unload", "lift"};
  EXPECT_TRUE(check_operations(*order, status));
  status.actions = {"load", "unload"};
  const auto refused = check_operations(*order, status);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(refused.error().message,
            "order 'o': destination 2: vehicle 'V1' does not perform 'lift' (its RAN performs: load, unload)");
}

// ---- RAN commands ----

/// A status of sequence `sequence` that lists the commands `listed` (running).
ran::VehicleStatus status_listing(std::uint64_t sequence, std::vector<std::string> listed) {
  ran::VehicleStatus status;
  status.sequence = sequence;
  for (auto& id : listed) status.commands.push_back(ran::CommandProgress{std::move(id), ran::CommandState::running, "", ""});
  return status;
}

TEST(CommandWatch, ARanThatDropsACommandWithoutEndingItLosesIt) {
  using namespace std::chrono_literals;
  using Loss = CommandWatch::Loss;
  const auto t0 = CommandWatch::Clock::time_point{} + 100s;
  CommandWatch watch(t0, 3s);
  // Statuses that crossed the reply, then the one that lists it: nothing lost.
  EXPECT_EQ(watch.observe(status_listing(7, {"older"}), "m1", t0 + 1s), Loss::none);
  EXPECT_EQ(watch.observe(status_listing(8, {"m1"}), "m1", t0 + 2s), Loss::none);
  EXPECT_EQ(watch.observe(status_listing(8, {"m1"}), "m1", t0 + 9s), Loss::none);  // seen before
  // A later status of the same RAN without it, its end never seen: dropped.
  EXPECT_EQ(watch.observe(status_listing(9, {}), "m1", t0 + 10s), Loss::dropped);
  EXPECT_EQ(loss_text(Loss::dropped).rfind("is no longer reported by the RAN, which never reported its end", 0), 0u);
}

TEST(CommandWatch, ARanThatRestartedForgotTheCommand) {
  using namespace std::chrono_literals;
  const auto t0 = CommandWatch::Clock::time_point{} + 100s;
  CommandWatch watch(t0, 3s);
  EXPECT_EQ(watch.observe(status_listing(40, {"m1", "m2"}), "m2", t0), CommandWatch::Loss::none);
  EXPECT_EQ(watch.observe(status_listing(2, {}), "m2", t0 + 1s), CommandWatch::Loss::restarted);
  EXPECT_EQ(loss_text(CommandWatch::Loss::restarted), "is no longer reported by the RAN, which restarted");
}

TEST(CommandWatch, ACommandNeverListedIsLostOnlyOnceTheGraceIsOver) {
  using namespace std::chrono_literals;
  const auto t0 = CommandWatch::Clock::time_point{} + 100s;
  CommandWatch watch(t0, 3s);
  // Statuses received up to the grace may predate the command (status and reply travel apart).
  EXPECT_EQ(watch.observe(status_listing(5, {}), "m1", t0 - 1s), CommandWatch::Loss::none);
  EXPECT_EQ(watch.observe(status_listing(6, {}), "m1", t0 + 3s), CommandWatch::Loss::none);
  EXPECT_EQ(watch.observe(status_listing(7, {}), "m1", t0 + 3s + 1ms), CommandWatch::Loss::never_listed);
  // Listed late but within the grace, it is followed from then on.
  CommandWatch late(t0, 3s);
  EXPECT_EQ(late.observe(status_listing(6, {"m1"}), "m1", t0 + 2s), CommandWatch::Loss::none);
  EXPECT_EQ(late.observe(status_listing(7, {"m1"}), "m1", t0 + 60s), CommandWatch::Loss::none);
}

// ---- route tracking ----

TEST(LateGrants, GivesBackWhatNobodyClaimsAndKeepsTheCurrentRoutesGrantsForTheirClaim) {
  using namespace std::chrono_literals;
  LateGrants grants(2s);
  const auto t0 = LateGrants::Clock::time_point{} + 100s;
  grants.granted(4, HeldStep{7, 2}, t0);  // of the current route 7: its claim may come
  grants.granted(5, HeldStep{6, 1}, t0);  // of route 6, given up since
  grants.granted(9, HeldStep{7, 4}, t0);  // claimed by an allocate reply in the meantime
  const auto held = [](topology::EntityIndex entity) { return entity == 9; };
  using Released = std::vector<std::pair<topology::EntityIndex, HeldStep>>;
  EXPECT_EQ(grants.to_release(held, 7, t0 + 1s), (Released{{5, HeldStep{6, 1}}}));
  EXPECT_EQ(grants.to_release(held, 7, t0 + 1s), Released{});  // each is returned once
  EXPECT_FALSE(grants.empty());
  // Unclaimed for longer than the claim may take: given back too.
  EXPECT_EQ(grants.to_release(held, 7, t0 + 3s), (Released{{4, HeldStep{7, 2}}}));
  EXPECT_TRUE(grants.empty());
  // Without a current route nothing waits for a claim.
  grants.granted(4, HeldStep{7, 2}, t0);
  EXPECT_EQ(grants.to_release(held, std::nullopt, t0), (Released{{4, HeldStep{7, 2}}}));
}

TEST(RouteTracker, AllocatesWithinTheLookAheadAndMovesOnlyOntoAllocatedSteps) {
  const auto world = h_crossing();
  RouteTracker route = left_route(world);
  route.mark_allocated();  // the start vertex
  // Look-ahead of one vertex: the edge and the next vertex, then stop.
  EXPECT_EQ(route.next_to_allocate(route.position_step(), 1), 1u);
  route.mark_allocated();
  EXPECT_FALSE(route.next_move()) << "the target vertex is not allocated yet";
  EXPECT_EQ(route.next_to_allocate(route.position_step(), 1), 2u);
  route.mark_allocated();
  EXPECT_FALSE(route.next_to_allocate(route.position_step(), 1)) << "beyond the look-ahead";
  ASSERT_EQ(route.next_move(), 1u);
  const auto move = route.command_move(1, "m1", 2.0);
  EXPECT_EQ(move.target_vertex, "left-1");
  EXPECT_EQ(move.edge, "left-0<->left-1");
  EXPECT_DOUBLE_EQ(move.max_speed, 1.0) << "the edge's limit";
  ASSERT_EQ(move.area.size(), 3u);
  EXPECT_TRUE(boost::geometry::equals(move.area[0], world->footprint(index(*world, "left-0"))));
  EXPECT_FALSE(route.next_move());
  EXPECT_EQ(route.position_step(), 1u) << "on the edge while the move runs";
  route.mark_reached(2);
  EXPECT_EQ(route.position_step(), 2u);
  EXPECT_EQ(route.next_to_allocate(route.position_step(), 1), 3u);
  EXPECT_FALSE(route.arrived());
  route.mark_reached(6);
  EXPECT_TRUE(route.arrived());
}

TEST(RouteTracker, AMoveAlongAnEdgeGoesToEitherEndWithinTheEdgeAndBothEnds) {
  const auto world = h_crossing();
  const auto edge = index(*world, "left-0<->left-1");
  // Back along the bidirectional edge, as a vehicle stopped part-way on it may drive.
  const auto back = move_along(*world, edge, index(*world, "left-0"), "m7", 0.5);
  EXPECT_EQ(back.id, "m7");
  EXPECT_EQ(back.target_vertex, "left-0");
  EXPECT_EQ(back.edge, "left-0<->left-1");
  EXPECT_DOUBLE_EQ(back.max_speed, 0.5) << "the vehicle's limit, below the edge's";
  EXPECT_DOUBLE_EQ(back.target.x, world->vertex(index(*world, "left-0")).position.x());
  EXPECT_DOUBLE_EQ(back.target.y, world->vertex(index(*world, "left-0")).position.y());
  ASSERT_EQ(back.area.size(), 3u);
  EXPECT_TRUE(boost::geometry::equals(back.area[0], world->footprint(index(*world, "left-1"))));
  EXPECT_TRUE(boost::geometry::equals(back.area[1], world->footprint(edge)));
  EXPECT_TRUE(boost::geometry::equals(back.area[2], world->footprint(index(*world, "left-0"))));
}

TEST(RouteTracker, FollowsDelaysAndMeasuresLateness) {
  const auto world = h_crossing();
  carp::VehicleProfile vehicle;
  vehicle.max_speed = 1.0;
  vehicle.acceleration = 0.5;
  vehicle.deceleration = 0.5;
  RouteTracker route = left_route(world);
  // Standing at left-0 at time 0: planned at left-1 (3 m) at 3 s; the trapezoid needs 5 s.
  auto late = route.lateness(topology::Point(0, 0), 0, vehicle, 0);
  ASSERT_TRUE(late);
  EXPECT_EQ(*late, seconds_to_ns(2));
  EXPECT_DOUBLE_EQ(route.remaining_distance(topology::Point(0, 0), 6), 3 + 3 + 2.5);
  // A delay of 4 s from step 1 on: left-1 is planned at 7 s, so the vehicle is early.
  route.shift(1, seconds_to_ns(4));
  EXPECT_EQ(route.step(2).window.start, seconds_to_ns(7));
  EXPECT_EQ(route.step(6).window.end, kForever) << "open ends stay open";
  EXPECT_EQ(*route.lateness(topology::Point(0, 0), 0, vehicle, 0), seconds_to_ns(-2));
  // Stalled half-way at 6 s: 1.5 m from rest take sqrt(12) s.
  EXPECT_NEAR(ns_to_seconds(*route.lateness(topology::Point(0, 1.5), 0, vehicle, seconds_to_ns(6))),
              6 + std::sqrt(12.0) - 7, 1e-6);
}

TEST(TravelTime, TrapezoidAndTriangle) {
  carp::VehicleProfile vehicle;
  vehicle.max_speed = 1.0;
  vehicle.acceleration = 0.5;
  vehicle.deceleration = 1.0;
  EXPECT_EQ(drive_time(0, 0, vehicle), 0);
  // Cruise: 1 s + 2 m ramping... accel 2 s (1 m), brake 1 s (0.5 m), 8.5 m at 1 m/s.
  EXPECT_EQ(drive_time(10, 0, vehicle), seconds_to_ns(2 + 1 + 8.5));
  // Triangle from rest: v^2 (1/(2a) + 1/(2d)) = 0.75 -> v = sqrt(0.5).
  EXPECT_NEAR(ns_to_seconds(drive_time(0.75, 0, vehicle)), std::sqrt(0.5) / 0.5 + std::sqrt(0.5), 1e-6);
  // Already at speed: no acceleration phase.
  EXPECT_EQ(drive_time(10, 1.0, vehicle), seconds_to_ns(1 + 9.5));
  // Too short to brake in: covered while braking.
  EXPECT_EQ(drive_time(0.25, 1.0, vehicle), seconds_to_ns(0.5));
}

// ---- footprints ----

TEST(FootprintMonitor, FootprintMustStayInsideTheHeldEntities) {
  const auto world = h_crossing();
  FootprintMonitor monitor(world);
  monitor.hold(index(*world, "left-0"), HeldStep{1, 0});
  EXPECT_TRUE(monitor.inside(status_at(0, 0).footprint));
  EXPECT_FALSE(monitor.inside(status_at(0, 1.0, 1.5707963).footprint)) << "on the edge, not held";
  monitor.hold(index(*world, "left-0<->left-1"), HeldStep{1, 1});
  EXPECT_TRUE(monitor.inside(status_at(0, 1.0, 1.5707963).footprint));
  EXPECT_FALSE(monitor.inside(status_at(1.0, 1.0).footprint)) << "beside the edge";
}

/// A vehicle leaving left-0 for left-1, holding left-0 (step 0) and the edge (step 1).
struct LeavingLeft0 : ::testing::Test {
  std::shared_ptr<const topology::Topology> world = h_crossing();
  FootprintMonitor monitor{world};
  topology::EntityIndex start = index(*world, "left-0");
  topology::EntityIndex edge = index(*world, "left-0<->left-1");
  topology::EntityIndex next = index(*world, "left-1");
  LeavingLeft0() {
    monitor.hold(start, HeldStep{1, 0});
    monitor.hold(edge, HeldStep{1, 1});
  }
};

TEST_F(LeavingLeft0, ReleasesWhatThePassedVehicleNoLongerTouches) {
  monitor.hold(next, HeldStep{1, 2});
  // Still at the start: nothing to release, the edge ahead is not passed.
  EXPECT_TRUE(monitor.releasable(status_at(0, 0, 1.5707963).footprint, 0).empty());
  // Leaving, half on left-0 and half on the edge: left-0 is still needed.
  EXPECT_TRUE(monitor.releasable(status_at(0, 0.3, 1.5707963).footprint, 0).empty());
  // On the edge, clear of left-0.
  EXPECT_EQ(monitor.releasable(status_at(0, 1.5, 1.5707963).footprint, 0), std::vector{start});
  monitor.drop(start);
  // Arrived at left-1: the edge is passed and no longer touched.
  EXPECT_EQ(monitor.releasable(status_at(0, 3, 1.5707963).footprint, 2), std::vector{edge});
  // Leftovers of an earlier route count as passed.
  monitor.hold(index(*world, "bar-1"), HeldStep{1, 9});
  monitor.forget_steps();
  const auto leftovers = monitor.releasable(status_at(0, 3, 1.5707963).footprint, 0);
  EXPECT_EQ(leftovers, (std::vector{index(*world, "bar-1"), edge})) << "ascending by entity";
  // A leftover keeps the step it was granted as: a cancel of its route keeps that step, and
  // its release gives up the step's shadows in other partitions.
  EXPECT_EQ(monitor.granted_as(edge), (HeldStep{1, 1}));
  EXPECT_EQ(monitor.held_steps_of(1), (std::vector<std::uint32_t>{1, 2, 9}));
  EXPECT_TRUE(monitor.held_steps_of(2).empty());
  EXPECT_FALSE(monitor.granted_as(start).has_value()) << "dropped";
}

TEST_F(LeavingLeft0, ReleasesWhatThePassedVehicleTouchesButNoLongerNeeds) {
  // On left-1, turned across the aisle: the footprint touches the edge's strip beside it.
  const auto footprint = status_at(0.3, 3).footprint;
  ASSERT_TRUE(boost::geometry::intersects(footprint, world->footprint(edge)));
  // Without left-1 held, the edge is still needed.
  EXPECT_EQ(monitor.releasable(footprint, 2), std::vector{start});
  // With left-1 held, the footprint lies inside left-1's own footprint, so the edge can go
  // (a route stepping aside onto left-1 lets another vehicle use the edge meanwhile).
  monitor.hold(next, HeldStep{1, 2});
  EXPECT_EQ(monitor.releasable(footprint, 2), (std::vector{start, edge}));
  // Not passed yet: kept, however covered.
  EXPECT_EQ(monitor.releasable(footprint, 0), std::vector{start});
}

// ---- vehicle profiles ----

TEST(VehicleProfileJson, ParsesAndNamesBadFields) {
  auto vehicle = carp::parse_vehicle_profile(R"({"id": "V1", "max_speed": 1.5, "acceleration": 0.5})", "v.json");
  ASSERT_TRUE(vehicle);
  EXPECT_EQ(vehicle->id, "V1");
  EXPECT_DOUBLE_EQ(vehicle->max_speed, 1.5);
  EXPECT_DOUBLE_EQ(vehicle->acceleration, 0.5);
  auto unknown = carp::parse_vehicle_profile(R"({"speed": 1})", "v.json");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("v.json: speed: unknown field"), std::string::npos);
  auto wrong = carp::parse_vehicle_profile(R"({"max_speed": "fast"})", "v.json");
  ASSERT_FALSE(wrong);
  EXPECT_EQ(wrong.error().code, ErrorCode::parse);
  auto range = carp::parse_vehicle_profile(R"({"max_speed": -1})", "v.json");
  ASSERT_FALSE(range);
  EXPECT_EQ(range.error().code, ErrorCode::invalid_argument);
  EXPECT_FALSE(carp::parse_vehicle_profile("{", "v.json"));
  auto huge = carp::parse_vehicle_profile(R"({"max_speed": 1e400})", "v.json");
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().code, ErrorCode::parse);
  EXPECT_EQ(huge.error().message,
            "v.json:line 1, column 19: malformed JSON: number overflow parsing '1e400'");
  EXPECT_EQ(carp::read_vehicle_profile("/nonexistent/v.json").error().code, ErrorCode::io);
  EXPECT_EQ(carp::read_vehicle_profile("/dev/zero").error().message,
            "/dev/zero: is a device or socket, not a file");
}

// JSON allows a key twice and the parser keeps the last value; a NUL byte ends its text. A
// profile must not silently lose a value either way.
TEST(VehicleProfileJson, KeysGivenTwiceAndNulBytesAreRefused) {
  auto twice = carp::parse_vehicle_profile(R"({"max_speed": 1, "width": 0.5, "max_speed": 10})", "v.json");
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().code, ErrorCode::parse);
  EXPECT_EQ(twice.error().message, "v.json:max_speed: key given twice in the same object");
  auto two = carp::parse_vehicle_profile(R"({"id": "a", "width": 1, "id": "b", "width": 2})", "v.json");
  ASSERT_FALSE(two);
  EXPECT_EQ(two.error().message,
            "v.json:id: key given twice in the same object; v.json:width: key given twice in the same object");
  auto nul = carp::parse_vehicle_profile(std::string(R"({"max_speed": 1})") + "\n  " + '\0' + R"({"max_speed": 9})",
                                         "v.json");
  ASSERT_FALSE(nul);
  EXPECT_EQ(nul.error().code, ErrorCode::parse);
  EXPECT_EQ(nul.error().message, "v.json:line 2, column 3: malformed JSON: NUL byte (a JSON text cannot contain one)");
}

}  // namespace
}  // namespace drover::logical_agent

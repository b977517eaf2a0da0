// minimal_ran: a straight-line vehicle behind Drover's VehicleDriver interface.
//
//   minimal_ran VEHICLE_ID [DOMAIN]   runs it as a robot agent node on DDS until SIGINT:
//                                     commands on drover/ran/command, status on
//                                     drover/ran/status (agent id ran-VEHICLE_ID)
//   minimal_ran --self-test           drives it through a short scenario (a move, a load,
//                                     a move back, two commands it must refuse) with a sink
//                                     that prints every report; exits 0 when every command
//                                     ended as expected

#include <cstdio>
#include <cstdlib>
#include <string>

#include <drover/ran/vehicle_driver.hpp>
#include <drover/ran_runner/runner.hpp>

#include "straight_line_driver.hpp"

using namespace drover;
using namespace drover::ran;

namespace {

/// Prints one line per report; a runner would publish it instead.
class PrintingSink final : public StatusSink {
 public:
  VehicleStatus last;

 protected:
  void deliver(const VehicleStatus& status) override {
    last = status;
    std::printf("#%llu t=%.1fs pose=(%.2f, %.2f) speed=%.2f load=%s",
                static_cast<unsigned long long>(status.sequence), ns_to_seconds(status.time),
                status.pose.x, status.pose.y, status.linear_speed, to_string(status.load));
    for (const auto& command : status.commands) {
      std::printf(" %s:%s", command.id.c_str(), to_string(command.state));
    }
    std::printf("\n");
  }
};

/// The corridor y in [-0.5, 0.5], x in [-1, 4]: the only area these moves may use.
MotionArea corridor() {
  return MotionArea{topology::Polygon{{{-1, -0.5}, {-1, 0.5}, {4, 0.5}, {4, -0.5}, {-1, -0.5}}}};
}

MoveCommand move_to(std::string id, std::string vertex, double x, double y) {
  return MoveCommand{std::move(id), std::move(vertex), {x, y, {}}, "e", 0.5, corridor()};
}

bool ended_as(const VehicleStatus& status, const char* id, CommandState state) {
  const auto* command = status.find_command(id);
  return command != nullptr && command->state == state;
}

}  // namespace

int self_test() {
  StraightLineDriver driver("minimal-1", Pose{0, 0, 0});
  PrintingSink sink;
  TimeNs now = 0;
  driver.start(sink, now);
  driver.on_move(move_to("there", "P3", 3, 0), now);
  driver.on_action(ActionCommand{"pick", ActionKind::load, "", {}}, now);
  driver.on_move(move_to("back", "P0", 0, 0), now);
  driver.on_move(move_to("there", "P3", 3, 0), now);  // sent again: never driven twice
  driver.on_move(move_to("outside", "Q", 0, 2), now);  // leaves the corridor: refused
  driver.on_action(ActionCommand{"charge", ActionKind::charge, "", {}}, now);  // unsupported
  while (!driver.idle() && now < seconds_to_ns(60)) {
    now += seconds_to_ns(0.5);
    driver.on_tick(now);
  }
  const auto& status = sink.last;
  const bool as_expected = ended_as(status, "there", CommandState::finished) &&
                           ended_as(status, "pick", CommandState::finished) &&
                           ended_as(status, "back", CommandState::finished) &&
                           ended_as(status, "outside", CommandState::rejected) &&
                           ended_as(status, "charge", CommandState::rejected) &&
                           status.load == LoadState::loaded && status.pose.x == 0;
  std::printf("%s\n", as_expected ? "minimal_ran: all commands ended as expected"
                                  : "minimal_ran: unexpected outcome");
  return as_expected ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--self-test") return self_test();
  if (argc < 2 || argc > 3 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: minimal_ran VEHICLE_ID [DOMAIN] | minimal_ran --self-test\n");
    return 2;
  }
  RanNodeOptions options;
  options.vehicle_id = argv[1];
  if (argc == 3) {
    char* end = nullptr;
    const unsigned long domain = std::strtoul(argv[2], &end, 10);
    if (*end != '\0' || domain > 232) {
      std::fprintf(stderr, "error: DOMAIN '%s' is not a DDS domain id (0..232)\n", argv[2]);
      return 2;
    }
    options.domain_id = static_cast<std::uint32_t>(domain);
  }
  StraightLineDriver driver(options.vehicle_id, Pose{0, 0, 0});
  // Everything DDS (participant, heartbeat, command service, status topic, SIGINT) is the
  // runner's: the driver above is all an integrator writes.
  const auto ran = run_ran_node(driver, options, SharedClock::wall());
  if (!ran) {
    std::fprintf(stderr, "error: %s\n", ran.error().message.c_str());
    return 1;
  }
  return 0;
}

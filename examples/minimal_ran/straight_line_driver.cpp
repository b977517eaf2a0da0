#include "straight_line_driver.hpp"

#include <algorithm>
#include <cmath>

#include <drover/ran/motion_area.hpp>
#include <drover/ran/validation.hpp>

using namespace drover;
using namespace drover::ran;

namespace {
constexpr double kTopSpeed = 0.5;        // m/s, whatever the command allows
constexpr double kOperationSeconds = 1;  // every supported action
const topology::Polygon kOutline{{{-0.3, -0.2}, {-0.3, 0.2}, {0.3, 0.2}, {0.3, -0.2}, {-0.3, -0.2}}};
}  // namespace

CommandId StraightLineDriver::id_of(const Command& command) {
  return std::visit([](const auto& c) { return c.id; }, command);
}

StraightLineDriver::StraightLineDriver(std::string vehicle_id, Pose start) : planned_end_(start) {
  status_.vehicle_id = std::move(vehicle_id);
  status_.pose = start;
  status_.load = LoadState::empty;
  // What it performs, advertised: an order asking this vehicle for anything else (charge,
  // a custom action) is refused when it is sent, not failed at its destination.
  status_.actions = {"load", "unload"};
}

void StraightLineDriver::start(StatusSink& sink, TimeNs now) {
  sink_ = &sink;
  last_update_ = now;
  report(now);
}

void StraightLineDriver::stop(TimeNs now) {
  advance(now);
  sink_ = nullptr;  // the runner is going away: report no more
}

void StraightLineDriver::on_move(const MoveCommand& command, TimeNs now) {
  advance(now);
  // Driving straight from where the previous move ends: the swept footprint must stay
  // inside the motion area.
  const double dx = command.target.x - planned_end_.x, dy = command.target.y - planned_end_.y;
  const double heading = std::hypot(dx, dy) > 0 ? std::atan2(dy, dx) : planned_end_.theta;
  const auto start = footprint_at(kOutline, Pose{planned_end_.x, planned_end_.y, heading});
  if (status_.find_command(command.id) != nullptr) {
    // Sent again (a retry): never done twice; its report stays the original's.
  } else if (auto valid = validate(command); !valid) {
    reject(command.id, valid.error());
  } else if (area_outside(swept_by_translation(start, dx, dy), normalized_area(command.area)) >
             1e-4) {
    reject(command.id, {rejection_code::kOutsideArea, "the straight line leaves the motion area"});
  } else {
    planned_end_ = Pose{command.target.x, command.target.y, heading};
    accept(command, std::hypot(dx, dy));
  }
  report(now);
}

void StraightLineDriver::on_action(const ActionCommand& command, TimeNs now) {
  advance(now);
  if (status_.find_command(command.id) != nullptr) {
    // Sent again (a retry): never done twice; its report stays the original's.
  } else if (auto valid = validate(command); !valid) {
    reject(command.id, valid.error());
  } else if (command.kind == ActionKind::charge || command.kind == ActionKind::custom) {
    reject(command.id, {rejection_code::kUnsupportedAction, "this vehicle only loads and unloads"});
  } else {
    accept(command, kOperationSeconds);
  }
  report(now);
}

void StraightLineDriver::on_cancel(const CommandId& command, TimeNs now) {
  advance(now);
  // Cancel the command and everything queued after it; this vehicle stops at once.
  std::size_t index = 0;
  while (index < queue_.size() && id_of(queue_[index].command) != command) ++index;
  while (queue_.size() > index) {
    set_state(id_of(queue_.back().command), CommandState::cancelled, "", "cancelled");
    queue_.pop_back();
  }
  planned_end_ = status_.pose;
  for (const Queued& queued : queue_) {
    if (const auto* move = std::get_if<MoveCommand>(&queued.command)) {
      planned_end_ = Pose{move->target.x, move->target.y, move->target.theta.value_or(0)};
    }
  }
  report(now);
}

void StraightLineDriver::on_pause(TimeNs now) {
  advance(now);
  status_.paused = true;
  report(now);
}

void StraightLineDriver::on_resume(TimeNs now) {
  advance(now);
  status_.paused = false;
  report(now);
}

void StraightLineDriver::on_tick(TimeNs now) {
  advance(now);
  report(now);
}

void StraightLineDriver::advance(TimeNs now) {
  double seconds = ns_to_seconds(now - last_update_);
  last_update_ = now;
  status_.linear_speed = 0;
  while (!status_.paused && seconds > 0 && !queue_.empty()) {
    Queued& front = queue_.front();
    set_state(id_of(front.command), CommandState::running);
    if (const auto* move = std::get_if<MoveCommand>(&front.command)) {
      const double speed = std::min(kTopSpeed, move->max_speed);
      const double step = std::min(front.remaining, speed * seconds);
      const double dx = move->target.x - status_.pose.x, dy = move->target.y - status_.pose.y;
      const double distance = std::hypot(dx, dy);
      if (distance > 0) {
        status_.pose.theta = std::atan2(dy, dx);
        status_.pose.x += dx / distance * step;
        status_.pose.y += dy / distance * step;
      }
      front.remaining -= step;
      seconds -= step / speed;
      status_.linear_speed = speed;
      if (front.remaining > 1e-9) continue;
      status_.pose.x = move->target.x;
      status_.pose.y = move->target.y;
      status_.linear_speed = 0;
      if (move->target.theta) status_.pose.theta = *move->target.theta;
    } else {
      const double step = std::min(front.remaining, seconds);
      front.remaining -= step;
      seconds -= step;
      if (front.remaining > 1e-9) continue;
      const auto& action = std::get<ActionCommand>(front.command);
      status_.load = action.kind == ActionKind::load ? LoadState::loaded : LoadState::empty;
    }
    end_front(CommandState::finished, "");
  }
}

void StraightLineDriver::accept(Command command, double amount) {
  set_state(id_of(command), CommandState::accepted);
  queue_.push_back(Queued{std::move(command), amount});
}

void StraightLineDriver::reject(const CommandId& id, const Rejection& why) {
  set_state(id, CommandState::rejected, why.code, why.reason);
}

void StraightLineDriver::end_front(CommandState state, std::string reason) {
  set_state(id_of(queue_.front().command), state, "",
            std::move(reason));
  queue_.pop_front();
}

void StraightLineDriver::set_state(const CommandId& id, CommandState state, std::string code,
                                   std::string reason) {
  auto& commands = status_.commands;
  auto found = std::find_if(commands.begin(), commands.end(),
                            [&](const CommandProgress& c) { return c.id == id; });
  if (found == commands.end()) {
    commands.push_back({id, state, std::move(code), std::move(reason)});
  } else {
    *found = {id, state, std::move(code), std::move(reason)};
  }
  // Keep the status small: forget the oldest ended commands beyond the last 16.
  while (commands.size() > 16 && is_terminal(commands.front().state)) commands.erase(commands.begin());
}

void StraightLineDriver::report(TimeNs now) {
  status_.time = now;
  status_.footprint = footprint_at(kOutline, status_.pose);
  if (sink_ != nullptr) sink_->report(status_);
}

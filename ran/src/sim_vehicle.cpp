#include "drover/ran/sim_vehicle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <boost/geometry.hpp>
#include <fmt/format.h>

#include "drover/ran/motion_area.hpp"
#include "ran/src/speed_profile.hpp"

namespace drover::ran {

namespace {

/// Headings closer than this are the same direction: no turn between two straights.
constexpr double kHeadingTolerance = 1e-6;  // rad
/// A turn reached its target when it is this close.
constexpr double kTurnDone = 1e-9;  // rad
/// Moves shorter than this are turns on the spot.
constexpr double kMinStraight = 1e-6;  // m
/// Distances closer than this are equal (floating-point round-off).
constexpr double kRoundOff = 1e-9;  // m
/// A vehicle whose battery runs empty this close to the end of a straight still arrives.
constexpr double kArrivalSlack = 1e-6;  // m
/// A battery holding less than this is empty (round-off of the drain).
constexpr double kEnergyRoundOff = 1e-9;  // Wh
/// Turns are checked against the motion area at poses at most this far apart; a corner at
/// radius r then strays at most r (1 - cos(step / 2)) from the sampled outlines
/// (0.15 mm at r = 1 m), far below the default area tolerance.
constexpr double kTurnSampleStep = 2.0 * std::numbers::pi / 180.0;  // rad

double normalize_angle(double angle) {
  angle = std::remainder(angle, 2 * std::numbers::pi);
  return angle <= -std::numbers::pi ? angle + 2 * std::numbers::pi : angle;
}

/// The signed shortest turn from `from` to `to`, in (-pi, pi].
double turn_between(double from, double to) { return normalize_angle(to - from); }

/// Seconds to nanoseconds, rounded up, so that at the returned time an event is due.
/// `seconds` as whole ns, rounded up, at most kLatestTime: added to a time of the shared
/// clock's range it cannot overflow (a crawl at 1e-12 m/s would last 1e13 s).
DurationNs ceil_ns(double seconds) {
  const double ns = std::ceil(std::max(0.0, seconds) * 1e9);
  return ns >= static_cast<double>(kLatestTime) ? kLatestTime : static_cast<DurationNs>(ns);
}

Unexpected<Rejection> rejection(const char* code, std::string reason) {
  return unexpected(Rejection{code, std::move(reason)});
}

}  // namespace

Result<SimVehicle> SimVehicle::create(SimVehicleConfig config, Pose start, TimeNs now,
                                      std::shared_ptr<const topology::Topology> topology) {
  if (auto valid = config.validate(); !valid) return unexpected(valid.error());
  if (!std::isfinite(start.x) || !std::isfinite(start.y) || !std::isfinite(start.theta)) {
    return fail(ErrorCode::invalid_argument, "vehicle start pose is not finite");
  }
  boost::geometry::correct(config.footprint);
  return SimVehicle(std::move(config), start, now, std::move(topology));
}

SimVehicle::SimVehicle(SimVehicleConfig config, Pose start, TimeNs now,
                       std::shared_ptr<const topology::Topology> topology)
    : config_(std::move(config)),
      topology_(std::move(topology)),
      now_(now),
      position_(start.x, start.y),
      heading_(normalize_angle(start.theta)),
      energy_wh_(config_.battery_initial_wh),
      load_(config_.initial_load) {}

SimVehicle::SimVehicle(SimVehicle&&) noexcept = default;
SimVehicle& SimVehicle::operator=(SimVehicle&&) noexcept = default;
SimVehicle::~SimVehicle() = default;

// ---------------------------------------------------------------------------------------
// Commands

CommandCheck SimVehicle::reject(const CommandId& id, Rejection why) {
  record_ended(CommandProgress{id, CommandState::rejected, why.code, why.reason});
  changed();
  return unexpected(std::move(why));
}

bool SimVehicle::is_listed(const CommandId& id) const {
  const auto same = [&](const auto& entry) { return entry.id == id; };
  return std::any_of(tasks_.begin(), tasks_.end(), same) ||
         std::any_of(ended_.begin(), ended_.end(), same);
}

CommandCheck SimVehicle::admit(const CommandId& id) {
  if (!id.empty() && is_listed(id)) {
    // Not recorded: the id already names another command in the status.
    return rejection(rejection_code::kDuplicateId,
                     fmt::format("command id '{}' is already in use", id));
  }
  if (battery_failed_) {
    return reject(id, {rejection_code::kNotReady,
                       fmt::format("command '{}': the battery has failed", id)});
  }
  if (std::any_of(tasks_.begin(), tasks_.end(), [](const Task& task) { return task.cancel_requested; })) {
    // Braking for a cancel: a command queued now would start where the cancelled ones end,
    // and be cancelled with them once the vehicle stands. Slower than standing still, it
    // stands (as its status may have said already): the cancel completes first.
    if (!standing_still(speed_, angular_speed_)) {
      return reject(id, {rejection_code::kNotReady,
                         fmt::format("command '{}': the vehicle still brakes for a cancel; send it once it stands", id)});
    }
    remove_cancelled();
  }
  return {};
}

CommandCheck SimVehicle::submit(const MoveCommand& command) {
  if (auto admitted = admit(command.id); !admitted) return admitted;
  if (auto valid = validate(command); !valid) return reject(command.id, valid.error());
  if (battery_empty_) {
    return reject(command.id, {rejection_code::kNotReady,
                               fmt::format("move '{}': the battery is empty", command.id)});
  }
  const Pose start = planned_end();
  if (topology_) {
    auto fits = check_against_topology(command, *topology_, start, config_.position_tolerance);
    if (!fits) return reject(command.id, fits.error());
  }

  Task task;
  task.id = command.id;
  const Eigen::Vector2d from(start.x, start.y);
  const Eigen::Vector2d to(command.target.x, command.target.y);
  double heading = start.theta;
  if ((to - from).norm() > kMinStraight) {
    const Eigen::Vector2d direction = to - from;
    const double travel = std::atan2(direction.y(), direction.x());
    if (std::abs(turn_between(heading, travel)) > kHeadingTolerance) {
      task.steps.emplace_back(Rotation{travel});
    }
    task.steps.emplace_back(Straight{from, to, std::min(command.max_speed, config_.max_speed)});
    heading = travel;
  }
  if (command.target.theta &&
      std::abs(turn_between(heading, *command.target.theta)) > kHeadingTolerance) {
    heading = normalize_angle(*command.target.theta);
    task.steps.emplace_back(Rotation{heading});
  }
  task.end_pose = Pose{to.x(), to.y(), heading};
  task.area = normalized_area(command.area);
  if (task.area.empty()) {
    return reject(command.id,
                  {rejection_code::kMalformed,
                   fmt::format("move '{}': no part of the motion area is a valid polygon",
                               command.id)});
  }
  if (auto inside = check_motion_area(task.steps, start, task.area, command.id); !inside) {
    return reject(command.id, inside.error());
  }
  enqueue(std::move(task));
  return {};
}

CommandCheck SimVehicle::submit(const ActionCommand& command) {
  if (auto admitted = admit(command.id); !admitted) return admitted;
  if (auto valid = validate(command); !valid) return reject(command.id, valid.error());
  const std::string where = fmt::format("action '{}'", command.id);

  Operation operation;
  operation.kind = command.kind;
  switch (command.kind) {
    case ActionKind::load:
      operation.duration = config_.load_duration;
      break;
    case ActionKind::unload:
      operation.duration = config_.unload_duration;
      break;
    case ActionKind::charge: {
      double target = 1.0;
      if (const auto given = command.parameters.find("target"); given != command.parameters.end()) {
        char* end = nullptr;
        target = std::strtod(given->second.c_str(), &end);
        if (end == given->second.c_str() || *end != '\0' || !std::isfinite(target) ||
            target <= 0 || target > 1) {
          return reject(command.id,
                        {rejection_code::kInvalidParameter,
                         fmt::format("{}: parameter target = '{}' is not a state of charge in "
                                     "(0, 1]",
                                     where, given->second)});
        }
      }
      operation.charge_target_wh = target * config_.battery_capacity_wh;
      break;
    }
    case ActionKind::custom: {
      const auto supported = config_.custom_actions.find(command.name);
      if (supported == config_.custom_actions.end()) {
        return reject(command.id, {rejection_code::kUnsupportedAction,
                                   fmt::format("{}: custom action '{}' is not supported by "
                                               "vehicle '{}'",
                                               where, command.name, config_.vehicle_id)});
      }
      operation.duration = supported->second;
      break;
    }
  }
  Task task;
  task.id = command.id;
  task.steps.emplace_back(operation);
  task.end_pose = planned_end();
  enqueue(std::move(task));
  return {};
}

CommandCheck SimVehicle::cancel(const CommandId& command) {
  const auto found = std::find_if(tasks_.begin(), tasks_.end(),
                                  [&](const Task& task) { return task.id == command; });
  if (found == tasks_.end()) {
    return rejection(rejection_code::kUnknownCommand,
                     fmt::format("cancel: command '{}' is not queued or running", command));
  }
  const auto first = static_cast<std::size_t>(found - tasks_.begin());
  for (std::size_t i = first; i < tasks_.size(); ++i) tasks_[i].cancel_requested = true;
  changed();
  const bool head_moving_straight =
      first == 0 && profile_ && !tasks_.front().steps.empty() &&
      std::holds_alternative<Straight>(tasks_.front().steps.front());
  if (!head_moving_straight && first == 0) {
    // A turn or an operation stops at once.
    angular_speed_ = 0;
    remove_cancelled();
  } else if (first > 0 && !tasks_.front().cancel_requested &&
             speed_ * speed_ / (2 * config_.deceleration) <= distance_to_task(first) + kRoundOff) {
    // The vehicle can stop before it reaches the cancelled commands: drop them now. (Not
    // when the head is cancelled already: the vehicle brakes, and the rest goes with the
    // head once it stands, as a commander cancelling each command in turn has it.)
    remove_cancelled();
  }
  // Otherwise the vehicle brakes along its path and the rest is cancelled once it stands.
  replan_ = true;
  handle_events();
  return {};
}

void SimVehicle::pause() {
  if (paused_) return;
  paused_ = true;
  changed();
  replan_ = true;
  handle_events();
}

void SimVehicle::resume() {
  if (!paused_) return;
  paused_ = false;
  changed();
  replan_ = true;
  handle_events();
}

CommandCheck SimVehicle::check_motion_area(const std::deque<Step>& steps, const Pose& start,
                                           const MotionArea& area, const CommandId& id) const {
  const auto outside = [&](const topology::Polygon& shape) {
    return area_outside(shape, area) > config_.area_tolerance_m2;
  };
  const auto leaves = [&](const std::string& what) {
    return rejection(rejection_code::kOutsideArea,
                     fmt::format("move '{}': the vehicle would leave its motion area {}", id, what));
  };
  Pose pose = start;
  if (outside(footprint_at(config_.footprint, pose))) {
    return leaves(fmt::format("at its start pose ({:.3f}, {:.3f}, {:.3f})", pose.x, pose.y,
                              pose.theta));
  }
  for (const Step& step : steps) {
    if (const auto* rotation = std::get_if<Rotation>(&step)) {
      const double turn = turn_between(pose.theta, rotation->target_heading);
      const int samples = std::max(1, static_cast<int>(std::ceil(std::abs(turn) / kTurnSampleStep)));
      const double from = pose.theta;
      for (int i = 1; i <= samples; ++i) {
        pose.theta = from + turn * i / samples;
        if (outside(footprint_at(config_.footprint, pose))) {
          return leaves(fmt::format("turning at ({:.3f}, {:.3f}) towards heading {:.3f}", pose.x,
                                    pose.y, rotation->target_heading));
        }
      }
      pose.theta = rotation->target_heading;
    } else if (const auto* straight = std::get_if<Straight>(&step)) {
      const Eigen::Vector2d delta = straight->to - straight->from;
      pose.theta = std::atan2(delta.y(), delta.x());
      const auto placed = footprint_at(config_.footprint, pose);
      if (outside(swept_by_translation(placed, delta.x(), delta.y()))) {
        return leaves(fmt::format("driving from ({:.3f}, {:.3f}) to ({:.3f}, {:.3f})",
                                  straight->from.x(), straight->from.y(), straight->to.x(),
                                  straight->to.y()));
      }
      pose.x = straight->to.x();
      pose.y = straight->to.y();
    }
  }
  return {};
}

void SimVehicle::enqueue(Task task) {
  tasks_.push_back(std::move(task));
  changed();
  replan_ = true;
  handle_events();
}

double SimVehicle::distance_to_task(std::size_t index) const {
  // Along the straights the vehicle drives without stopping; a turn or an operation on
  // the way means it stops before `index` anyway.
  double distance = 0;
  for (std::size_t i = 0; i < index && i < tasks_.size(); ++i) {
    for (std::size_t s = 0; s < tasks_[i].steps.size(); ++s) {
      const auto* straight = std::get_if<Straight>(&tasks_[i].steps[s]);
      if (straight == nullptr) return std::numeric_limits<double>::infinity();
      distance += straight->length() - (i == 0 && s == 0 ? head_progress_ : 0.0);
    }
  }
  return distance;
}

// ---------------------------------------------------------------------------------------
// Faults

void SimVehicle::stop_at_once() {
  speed_ = 0;
  angular_speed_ = 0;
  profile_.reset();
  changed();
  replan_ = true;
  handle_events();
}

void SimVehicle::inject_stall(DurationNs duration) {
  // Saturated, as a lost connection is: a duration from the network may be anything.
  const TimeNs until = duration >= kForever - now_ ? kForever : now_ + std::max<DurationNs>(duration, 1);
  stalled_until_ = std::max(stalled_until_, until);
  stop_at_once();
}

void SimVehicle::trigger_protective_field() {
  protective_field_ = true;
  stop_at_once();
}

void SimVehicle::clear_protective_field() {
  if (!protective_field_) return;
  protective_field_ = false;
  changed();
  replan_ = true;
  handle_events();
}

void SimVehicle::fail_battery() {
  if (battery_failed_) return;
  battery_failed_ = true;
  fail_from(0, "battery_failure", "the battery failed");
  stop_at_once();
}

void SimVehicle::lose_connection(DurationNs duration) {
  disconnected_until_ =
      duration >= kForever - now_ ? kForever : now_ + std::max<DurationNs>(duration, 1);
  changed();
  replan_ = true;
  handle_events();
}

void SimVehicle::restore_connection() {
  if (disconnected_until_ == 0) return;
  disconnected_until_ = 0;
  changed();
  replan_ = true;
  handle_events();
}

bool SimVehicle::connected() const noexcept { return disconnected_until_ == 0; }

// ---------------------------------------------------------------------------------------
// Stepping

bool SimVehicle::can_operate() const noexcept {
  return !paused_ && !protective_field_ && !battery_failed_ && stalled_until_ == 0 &&
         disconnected_until_ == 0;
}

bool SimVehicle::can_move() const noexcept { return can_operate() && !battery_empty_; }

bool SimVehicle::stopped() const noexcept { return !profile_; }

double SimVehicle::profile_time(TimeNs time) const { return ns_to_seconds(time - profile_start_); }

const SimVehicle::Step* SimVehicle::front_step() const {
  if (tasks_.empty() || tasks_.front().steps.empty()) return nullptr;
  return &tasks_.front().steps.front();
}

void SimVehicle::step(DurationNs dt) {
  if (dt <= 0) return;
  const TimeNs end = now_ + dt;
  handle_events();
  while (now_ < end) {
    const TimeNs next = std::max(now_ + 1, next_event(end));
    advance_continuous(next);
    now_ = next;
    handle_events();
  }
}

void SimVehicle::advance_to(TimeNs time) {
  if (time > now_) step(time - now_);
}

TimeNs SimVehicle::next_event(TimeNs limit) const {
  TimeNs next = limit;
  const auto consider = [&](TimeNs time) {
    if (time > now_ && time < next) next = time;
  };
  if (stalled_until_ != 0) consider(stalled_until_);
  if (disconnected_until_ != 0 && disconnected_until_ != kForever) consider(disconnected_until_);
  const Step* step = front_step();
  if (step == nullptr) return next;
  if (profile_) {
    consider(profile_start_ + ceil_ns(profile_->duration()));
    if (const auto* straight = std::get_if<Straight>(step)) {
      if (const auto end = straight_end_time(straight->length())) consider(*end);
    }
    if (config_.drain_wh_per_metre > 0) {
      const double empty_at =
          profile_->distance_at(profile_time(now_)) + energy_wh_ / config_.drain_wh_per_metre;
      if (empty_at < profile_->distance()) {
        consider(std::max(now_ + 1, profile_start_ + ceil_ns(profile_->time_at(empty_at))));
      }
    }
  } else if (const auto* rotation = std::get_if<Rotation>(step); rotation && can_move()) {
    consider(now_ + ceil_ns(std::abs(turn_between(heading_, rotation->target_heading)) /
                            config_.angular_speed));
  } else if (const auto* operation = std::get_if<Operation>(step);
             operation && operation->started && can_operate()) {
    if (operation->kind == ActionKind::charge) {
      consider(now_ + ceil_ns((operation->charge_target_wh - energy_wh_) /
                              config_.charge_wh_per_second));
    } else {
      consider(now_ + (operation->duration - operation->elapsed));
    }
  }
  return next;
}

void SimVehicle::advance_continuous(TimeNs to) {
  const Step* step = front_step();
  if (step == nullptr) return;
  if (profile_) {
    const auto* straight = std::get_if<Straight>(step);
    if (straight == nullptr) return;  // handle_events drops such a profile
    const double before = profile_->distance_at(profile_time(now_));
    const double after = profile_->distance_at(profile_time(to));
    speed_ = profile_->speed_at(profile_time(to));
    const Eigen::Vector2d delta = straight->to - straight->from;
    const double length = delta.norm();
    head_progress_ = std::clamp(after - profile_head_start_, 0.0, length);
    position_ = straight->from + delta * (head_progress_ / length);
    heading_ = std::atan2(delta.y(), delta.x());
    energy_wh_ = std::max(0.0, energy_wh_ - config_.drain_wh_per_metre * (after - before));
    return;
  }
  const double seconds = ns_to_seconds(to - now_);
  if (const auto* rotation = std::get_if<Rotation>(step); rotation && can_move()) {
    const double turn = turn_between(heading_, rotation->target_heading);
    const double amount = std::min(std::abs(turn), config_.angular_speed * seconds);
    heading_ = normalize_angle(heading_ + std::copysign(amount, turn));
    angular_speed_ = std::copysign(config_.angular_speed, turn);
  } else if (const auto* operation = std::get_if<Operation>(step);
             operation && operation->started && can_operate()) {
    auto& running = std::get<Operation>(tasks_.front().steps.front());
    running.elapsed += to - now_;
    if (operation->kind == ActionKind::charge) {
      energy_wh_ = std::max(energy_wh_, std::min(operation->charge_target_wh,
                                                 energy_wh_ + config_.charge_wh_per_second * seconds));
    }
  }
}

void SimVehicle::handle_events() {
  bool progress = true;
  while (progress) {
    progress = false;
    if (stalled_until_ != 0 && now_ >= stalled_until_) {
      stalled_until_ = 0;
      changed();
      replan_ = true;
    }
    if (disconnected_until_ != 0 && now_ >= disconnected_until_) {
      disconnected_until_ = 0;
      changed();
      replan_ = true;
    }
    if (battery_empty_ && energy_wh_ > kEnergyRoundOff) {
      battery_empty_ = false;
      changed();
    }
    // Steps first: a straight that ends with the last watt-hour is done, not failed.
    if (finish_front_step()) progress = true;
    // Empty with distance still to go (a vehicle a round-off before the end of its
    // straight arrives; its next straight then fails).
    const Step* head = front_step();
    const auto* straight = head != nullptr ? std::get_if<Straight>(head) : nullptr;
    if (profile_ && straight != nullptr && config_.drain_wh_per_metre > 0 &&
        energy_wh_ <= kEnergyRoundOff && head_progress_ < straight->length() - kArrivalSlack) {
      battery_empty_ = true;
      energy_wh_ = 0;
      speed_ = 0;
      profile_.reset();
      fail_from(0, "battery_empty",
                fmt::format("the battery ran empty at ({:.3f}, {:.3f})", position_.x(),
                            position_.y()));
      progress = true;
    }
    if (profile_ && profile_time(now_) >= profile_->duration()) {
      speed_ = 0;
      profile_.reset();
      replan_ = true;
      progress = true;
    }
    if (!tasks_.empty() && tasks_.front().cancel_requested && stopped()) {
      remove_cancelled();
      progress = true;
    }
  }
  const Step* step = front_step();
  if (profile_ && (step == nullptr || !std::holds_alternative<Straight>(*step))) {
    // The run ended (its last straight is done) a round-off before the profile did.
    speed_ = 0;
    profile_.reset();
  }
  if (replan_) {
    replan_ = false;
    plan_motion();
  }
}

std::optional<TimeNs> SimVehicle::straight_end_time(double length) const {
  if (!profile_) return std::nullopt;
  const double end = profile_head_start_ + length;
  // A braking profile may stop short of the end.
  if (profile_->distance() < end - kRoundOff) return std::nullopt;
  return profile_start_ + ceil_ns(profile_->time_at(end));
}

bool SimVehicle::straight_done(double length) const {
  // Judged by time while a profile runs: near a stop the vehicle creeps, so a distance
  // tolerance would end the straight measurably early.
  if (profile_) {
    const auto end = straight_end_time(length);
    return end && now_ >= *end;
  }
  return head_progress_ >= length - kRoundOff;
}

bool SimVehicle::finish_front_step() {
  if (tasks_.empty()) return false;
  Task& head = tasks_.front();
  if (head.state == CommandState::accepted) {
    head.state = CommandState::running;
    changed();
  }
  if (head.steps.empty()) {
    end_task(0, CommandState::finished, "", "");
    // A run that continues into the next command keeps its profile.
    if (!profile_) replan_ = true;
    return true;
  }
  Step& step = head.steps.front();
  if (auto* rotation = std::get_if<Rotation>(&step)) {
    if (std::abs(turn_between(heading_, rotation->target_heading)) > kTurnDone) return false;
    heading_ = rotation->target_heading;
    angular_speed_ = 0;
    head.steps.pop_front();
    replan_ = true;
    return true;
  }
  if (auto* straight = std::get_if<Straight>(&step)) {
    const double length = straight->length();
    if (!straight_done(length)) return false;
    position_ = straight->to;
    head_progress_ = 0;
    profile_head_start_ += length;
    head.steps.pop_front();
    return true;
  }
  auto& operation = std::get<Operation>(step);
  if (!operation.started) {
    if (!can_operate()) return false;
    if (operation.kind == ActionKind::load && load_ == LoadState::loaded) {
      fail_from(0, "already_loaded", "load: the vehicle is already loaded");
      return true;
    }
    if (operation.kind == ActionKind::unload && load_ == LoadState::empty) {
      fail_from(0, "not_loaded", "unload: the vehicle carries no load");
      return true;
    }
    operation.started = true;
    changed();
  }
  const bool done = operation.kind == ActionKind::charge
                        ? energy_wh_ >= operation.charge_target_wh - 1e-9
                        : operation.elapsed >= operation.duration;
  if (!done) return false;
  if (operation.kind == ActionKind::load) load_ = LoadState::loaded;
  if (operation.kind == ActionKind::unload) load_ = LoadState::empty;
  head.steps.pop_front();
  changed();
  return true;
}

void SimVehicle::plan_motion() {
  // A turn proceeds only while the vehicle may move: held (paused, stalled, ...), it turns
  // no more and says so.
  if (!can_move()) angular_speed_ = 0;
  const Step* step = front_step();
  const bool on_straight = step != nullptr && std::holds_alternative<Straight>(*step);
  // Faults stop the vehicle at once (and zero the speed themselves); a pause, a lost link
  // or a cancelled command brakes.
  const bool halted = !on_straight || protective_field_ || battery_failed_ || battery_empty_ ||
                      stalled_until_ != 0;
  const bool brakes =
      paused_ || disconnected_until_ != 0 || (on_straight && tasks_.front().cancel_requested);
  profile_.reset();
  if (halted || (brakes && speed_ <= 0)) {
    speed_ = 0;
    return;
  }
  profile_start_ = now_;
  profile_head_start_ = -head_progress_;
  if (brakes) {
    profile_ = std::make_unique<SpeedProfile>(SpeedProfile::brake(speed_, config_.deceleration));
    return;
  }
  std::vector<ProfileSegment> segments;
  bool run_continues = true;
  for (std::size_t i = 0; i < tasks_.size() && run_continues; ++i) {
    if (i > 0 && tasks_[i].cancel_requested) break;
    for (std::size_t s = 0; s < tasks_[i].steps.size(); ++s) {
      const auto* straight = std::get_if<Straight>(&tasks_[i].steps[s]);
      if (straight == nullptr) {
        run_continues = false;
        break;
      }
      const double done = i == 0 && s == 0 ? head_progress_ : 0.0;
      segments.push_back({std::max(0.0, straight->length() - done), straight->speed_limit});
    }
  }
  auto planned =
      SpeedProfile::plan(segments, speed_, config_.acceleration, config_.deceleration);
  profile_ = std::make_unique<SpeedProfile>(
      planned ? std::move(*planned) : SpeedProfile::brake(speed_, config_.deceleration));
  if (profile_->duration() <= 0) {
    speed_ = 0;
    profile_.reset();
  }
}

// ---------------------------------------------------------------------------------------
// Bookkeeping

void SimVehicle::record_ended(CommandProgress progress) {
  ended_.push_back(std::move(progress));
  while (ended_.size() > config_.recent_commands) ended_.pop_front();
}

void SimVehicle::end_task(std::size_t index, CommandState state, std::string code,
                          std::string reason) {
  record_ended(CommandProgress{tasks_[index].id, state, std::move(code), std::move(reason)});
  tasks_.erase(tasks_.begin() + static_cast<std::ptrdiff_t>(index));
  // A command removed part-way along its straight (cancelled, failed) leaves no progress
  // behind; one that finished had popped its straights already.
  if (index == 0) head_progress_ = 0;
  changed();
}

void SimVehicle::fail_from(std::size_t index, const std::string& code, const std::string& reason) {
  if (index >= tasks_.size()) return;
  if (index == 0) {
    speed_ = 0;
    angular_speed_ = 0;
    profile_.reset();
  }
  const CommandId first = tasks_[index].id;
  end_task(index, CommandState::failed, code, reason);
  while (tasks_.size() > index) {
    end_task(index, CommandState::failed, "previous_failed",
             fmt::format("command '{}' before it failed: {}", first, reason));
  }
}

void SimVehicle::remove_cancelled() {
  const auto first = std::find_if(tasks_.begin(), tasks_.end(),
                                  [](const Task& task) { return task.cancel_requested; });
  const auto index = static_cast<std::size_t>(first - tasks_.begin());
  if (index == 0) {
    speed_ = 0;
    angular_speed_ = 0;
    profile_.reset();
  }
  while (tasks_.size() > index) end_task(index, CommandState::cancelled, "", "cancelled");
}

// ---------------------------------------------------------------------------------------
// Queries

Pose SimVehicle::planned_end() const {
  if (tasks_.empty()) return Pose{position_.x(), position_.y(), heading_};
  return tasks_.back().end_pose;
}

const MotionArea* SimVehicle::active_area() const {
  if (tasks_.empty() || tasks_.front().area.empty()) return nullptr;
  return &tasks_.front().area;
}

VehicleStatus SimVehicle::status() const {
  VehicleStatus status;
  status.vehicle_id = config_.vehicle_id;
  status.time = now_;
  status.pose = Pose{position_.x(), position_.y(), heading_};
  status.linear_speed = speed_;
  status.angular_speed = angular_speed_;
  status.battery.energy_wh = energy_wh_;
  status.battery.state_of_charge = energy_wh_ / config_.battery_capacity_wh;
  const Step* step = front_step();
  if (const auto* operation = step ? std::get_if<Operation>(step) : nullptr) {
    status.battery.charging =
        operation->kind == ActionKind::charge && operation->started && can_operate();
  }
  status.load = load_;
  status.paused = paused_;
  status.actions = {"load", "unload", "charge"};
  for (const auto& [name, duration] : config_.custom_actions) status.actions.push_back(name);
  for (const Task& task : tasks_) status.commands.push_back({task.id, task.state, "", ""});
  status.commands.insert(status.commands.end(), ended_.begin(), ended_.end());
  if (battery_failed_) {
    status.errors.push_back({ErrorLevel::fatal, "battery_failure",
                             "the battery failed; the vehicle can neither move nor operate"});
  }
  if (battery_empty_) {
    status.errors.push_back(
        {ErrorLevel::recoverable, "battery_empty", "the battery is empty; charge to move again"});
  }
  if (stalled_until_ != 0) {
    status.errors.push_back({ErrorLevel::recoverable, "stall",
                             fmt::format("the drive is stalled until t = {:.3f} s",
                                         ns_to_seconds(stalled_until_))});
  }
  if (protective_field_) {
    status.errors.push_back({ErrorLevel::recoverable, "protective_field",
                             "a protective field is interrupted; waiting until it is clear"});
  }
  status.footprint = footprint_at(config_.footprint, status.pose);
  return status;
}

}  // namespace drover::ran

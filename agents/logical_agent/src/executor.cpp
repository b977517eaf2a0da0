// The logical agent's executor thread: orders, routes, allocation ahead, moves, footprint
// and time-window monitoring, delays, locks, RAN errors, parking and charging.

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include <boost/geometry.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "agents/logical_agent/src/logical_agent.hpp"
#include "drover/dds/wire_error.hpp"

namespace drover::logical_agent {

namespace bg = boost::geometry;

namespace {

/// Pause (real time) between two route attempts the timelines or a missing agent refused.
constexpr std::chrono::milliseconds kRoutePause{500};
/// How long stop_vehicle waits for the vehicle to report standing still after a cancel.
constexpr std::chrono::seconds kStopWait{10};
/// A RAN silent for this long (real time) counts as a recoverable error ("ran_lost").
constexpr std::chrono::seconds kRanSilence{3};
/// After a failed attempt to reach a charger, the next one waits this long (shared clock).
constexpr DurationNs kChargeRetry = seconds_to_ns(30);
/// A vehicle that cannot hold its vertex keeps it reserved this far ahead (shared clock):
/// time to drive off once a way is found. Those due after it lose nothing when it leaves
/// sooner: allocation goes by order, not by time.
constexpr DurationNs kStrandedReserve = seconds_to_ns(30);
/// How often (shared clock) a vehicle that cannot hold its vertex tries to clear the way.
constexpr DurationNs kClearWayRetry = seconds_to_ns(10);

bool nobody_answered(const Error& error) {
  return error.code == ErrorCode::timeout || error.code == ErrorCode::unavailable;
}

std::string seconds_text(DurationNs ns) { return fmt::format("{:.1f} s", ns_to_seconds(ns)); }

}  // namespace

bool LogicalAgent::wait_event() {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, options_.tick, [&] { return stopping_ || events_ != seen_events_; });
  seen_events_ = events_;
  return !stopping_;
}

std::optional<ran::VehicleStatus> LogicalAgent::latest_status() {
  std::lock_guard lock(mutex_);
  return status_;
}

std::optional<ran::VehicleStatus> LogicalAgent::recent_standing_status() {
  std::lock_guard lock(mutex_);
  if (std::chrono::steady_clock::now() - status_received_ > kRanSilence || !fresh_and_standing(0)) return std::nullopt;
  return status_;
}

void LogicalAgent::run() {
  if (!take_over()) return;
  idle_since_ = clock_.now();
  while (!stopping_) {
    take_over_late();
    bool replan = false;
    process_notices(replan);
    if (!route_) {
      if (!hold_position()) {
        publish_vehicle_state(false);
        wait_event();
        continue;
      }
      set_activity(Activity::idle);
    }
    if (pause_requested() && !adopted_action_pending()) {
      // Holding its vertex, it begins nothing: no order, charging, parking or making way. A
      // withdrawal of the running order ends it now: the vehicle stands.
      set_activity(Activity::paused);
      end_pending_withdrawal();
      publish_vehicle_state(false);
      wait_event();
      continue;
    }
    if (activity_ == Activity::paused) set_activity(Activity::idle);  // resumed
    const auto status = latest_status();
    // A vehicle that says it does not charge (its RAN advertises its actions without
    // "charge") is never sent to a charger: it would only fail there.
    const bool battery_low = status && options_.charge_below > 0 && status->performs("charge") &&
                             status->battery.state_of_charge < options_.charge_below && !status->battery.charging;
    bool has_work = false;
    bool order_running = false;  // only after a restart: an order runs in execute_order otherwise
    {
      std::lock_guard lock(mutex_);
      order_running = book_.current() != nullptr;
      has_work = order_running || book_.queued_count() > 0;
    }
    if (battery_low && clock_.now() >= charge_retry_at_ && !order_running) {
      go_to_service_vertex(topology::VertexKind::charger);
      continue;
    }
    if (has_work) {
      {
        std::lock_guard lock(mutex_);
        if (!pause_) book_.start_next(clock_.now());  // a pause that came meanwhile starts nothing
      }
      execute_order();
      set_activity(Activity::idle);
      continue;
    }
    if (auto requester = make_way_requested()) {
      make_way(*requester);
      set_activity(Activity::idle);
      continue;
    }
    if (options_.park_after >= 0 && activity_ == Activity::idle && vertex_ &&
        topology_->vertex(*vertex_).kind != topology::VertexKind::parking &&
        clock_.now() - idle_since_ >= options_.park_after) {
      go_to_service_vertex(topology::VertexKind::parking);
      set_activity(Activity::idle);
      continue;
    }
    publish_vehicle_state(false);
    wait_event();
  }
  // Clean shutdown: the vehicle stops (it must not drive on into what is given up), future
  // reservations go; what the vehicle occupies stays allocated.
  stop_vehicle();
  if (route_) {
    spdlog::info("cancelling route {} on shutdown", route_->id());
    cancel_route_quietly(*route_);
  }
}

std::optional<topology::EntityIndex> LogicalAgent::vertex_under(const ran::VehicleStatus& status) const {
  const topology::Point position(status.pose.x, status.pose.y);
  std::optional<topology::EntityIndex> best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (topology::EntityIndex v = 0; v < topology_->vertex_count(); ++v) {
    if (!bg::covered_by(position, topology_->footprint(v))) continue;
    const double distance = bg::distance(position, topology_->vertex(v).position);
    if (distance < best_distance) {
      best = v;
      best_distance = distance;
    }
  }
  return best;
}

bool LogicalAgent::hold_position() {
  // Moves whose cancel did not reach the RAN are cancelled first (it must not drive on), and
  // a cancel is seen through until the vehicle stands.
  if (!stop_vehicle()) return false;
  std::optional<ran::VehicleStatus> status;
  {
    // Only a recent status says where the vehicle is (a RAN out of reach may have left it
    // anywhere on what it was allowed onto); that it stands, stop_vehicle saw to.
    std::lock_guard lock(mutex_);
    if (status_ && std::chrono::steady_clock::now() - status_received_ <= kRanSilence) status = status_;
  }
  // A RAN whose statuses are refused (told by an alarm when it began) is an error; while two
  // RANs report, what their last taken status says is no ground to command either.
  if (!status || ran_->two_rans()) {
    if (ran_->refusal(kRanSilence)) set_activity(Activity::error);
    return false;
  }
  if (earlier_commands_running(*status)) {
    set_activity(Activity::waiting);
    return false;
  }
  const auto vertex = vertex_under(*status);
  if (vertex && !take_over_late(topology_->partition(*vertex))) {
    // What an earlier life holds there is unknown: holding the vertex now would take over
    // its allocation unknowingly, and leave that life's route (and its turn on the vertex).
    set_activity(Activity::waiting);
    pause_before_retry();
    return false;
  }
  if (!vertex && finish_edge(*status)) return true;
  if (!vertex) {
    set_activity(Activity::error);
    if (!position_alarm_raised_) {
      raise_alarm(msg::ALARM_ERROR, fmt::format("vehicle '{}' at ({:.2f}, {:.2f}) stands on no vertex of '{}'",
                                                vehicle_id(), status->pose.x, status->pose.y, topology_->name()));
      position_alarm_raised_ = true;
    }
    return false;
  }
  vertex_ = vertex;
  std::string refusal;
  auto route = plan_route(*vertex, 0, false, &refusal);
  // Refused for good as things stand (another vehicle is due there, or a lock): stranded.
  // Anything else (a topology or routing agent not up yet, a version conflict) passes.
  if (!route && !stopping_ && (refusal == "no_window" || refusal == "locked")) {
    return stranded_on(*vertex, route.error().message);
  }
  Status held = route ? switch_route(std::move(*route)) : Status(unexpected(route.error()));
  if (!held) {
    spdlog::warn("cannot hold '{}' yet: {}", topology_->id(*vertex), held.error().message);
    pause_before_retry();
    return false;
  }
  position_alarm_raised_ = false;
  hold_alarm_raised_ = false;
  critical_stop_ = false;  // it stands on a vertex again
  spdlog::info("vehicle '{}' holds '{}'", vehicle_id(), topology_->id(*vertex));
  release_passed(*status);  // what an earlier route left allocated and the vehicle does not need
  return true;
}

bool LogicalAgent::finish_edge(const ran::VehicleStatus& status) {
  const bool stopped_by_error = std::any_of(status.errors.begin(), status.errors.end(), [](const auto& error) {
    return error.level != ran::ErrorLevel::warning;
  });
  // After a critical alarm (a fatal RAN error, a footprint that left its area) the vehicle
  // moves only once someone has put it on a vertex; a paused one begins nothing.
  if (critical_stop_ || stopped_by_error || clock_.now() < finish_edge_at_ || pause_requested() ||
      !monitor_.inside(status.footprint)) {
    return false;
  }
  const topology::Point position(status.pose.x, status.pose.y);
  std::optional<topology::EntityIndex> on;
  for (const auto entity : monitor_.held()) {
    if (topology_->is_edge(entity) && bg::covered_by(position, topology_->footprint(entity))) on = entity;
  }
  if (!on) return false;
  finish_edge_at_ = clock_.now() + kClearWayRetry;  // when this attempt fails, the next one
  const auto& edge = topology_->edge(*on);
  const auto& from = topology_->vertex(edge.from).position;
  const auto& to = topology_->vertex(edge.to).position;
  const double ahead =
      std::cos(status.pose.theta) * (to.x() - from.x()) + std::sin(status.pose.theta) * (to.y() - from.y());
  const auto target = !edge.bidirectional || ahead >= 0 ? edge.to : edge.from;
  spdlog::info("vehicle '{}' stands part-way along '{}': it drives on to '{}'", vehicle_id(), edge.id,
               topology_->id(target));
  // The route holds the vertex it drives to; the edge it stands on it holds already.
  const auto last_vertex = vertex_;
  vertex_ = target;
  auto route = plan_route(target, 0, false);
  Status held = route ? switch_route(std::move(*route)) : Status(unexpected(route.error()));
  if (!held) {
    spdlog::warn("vehicle '{}' cannot drive on to '{}' yet: {}", vehicle_id(), topology_->id(target),
                 held.error().message);
    vertex_ = last_vertex;
    return false;
  }
  const auto move = move_along(*topology_, *on, target, next_command_id(), options_.vehicle.max_speed);
  auto verdict = ran_->move(move, options_.call_timeout);
  if (verdict && !verdict->rejected()) {
    pending_moves_.push_back(PendingMove{move.id, 0, watch_from_now()});
    drive_activity_ = Activity::driving;  // no order runs: nothing can be withdrawn
    driving_onto_ = target;
    std::string failure;
    const FollowResult result = follow(failure);
    driving_onto_.reset();
    if (result == FollowResult::arrived) {
      position_alarm_raised_ = false;
      return true;
    }
    spdlog::warn("vehicle '{}' did not drive on to '{}': {}", vehicle_id(), topology_->id(target), failure);
  } else {
    spdlog::warn("vehicle '{}' cannot drive on to '{}': the RAN {}", vehicle_id(), topology_->id(target),
                 verdict ? "rejected the move: " + verdict->code + " " + verdict->reason
                         : "did not take the move: " + verdict.error().message);
    if (!verdict) pending_moves_.push_back(PendingMove{move.id, 0, watch_from_now()});  // cancelled by stop_vehicle
  }
  // Still part-way along the edge: what the route holds of the vertex ahead goes with it.
  abandon_route();
  vertex_ = last_vertex;
  return false;
}

bool LogicalAgent::stranded_on(topology::EntityIndex vertex, const std::string& why) {
  keep_standing_reserved(vertex, kStrandedReserve + clock_.to_sim(2 * kRoutePause));
  const bool paused = pause_requested();
  if (!hold_alarm_raised_) {
    raise_alarm(msg::ALARM_WARNING,
                fmt::format("vehicle '{}' cannot hold '{}' ({}): it keeps it reserved, so that the vehicles due "
                            "there wait behind it, and {}",
                            vehicle_id(), topology_->id(vertex), why,
                            paused ? "stays there while it is paused" : "tries to clear the way to a parking vertex"));
    hold_alarm_raised_ = true;
  } else {
    spdlog::debug("cannot hold '{}' yet: {}", topology_->id(vertex), why);
  }
  bool action_pending = false;  // the restored order's, while the RAN runs it: the vehicle stays
  {
    std::lock_guard lock(mutex_);
    if (adopted_command_ && status_) {
      const auto* progress = status_->find_command(*adopted_command_);
      action_pending = progress != nullptr && !ran::is_terminal(progress->state);
    }
  }
  if (paused) end_pending_withdrawal();  // the vehicle stands: as in the run loop's pause
  if (clock_.now() >= clear_way_at_ && !action_pending && !paused) {
    clear_way_at_ = clock_.now() + kClearWayRetry;
    if (drive_to_nearest(topology::VertexKind::parking, false)) {
      spdlog::info("vehicle '{}' cleared the way: it holds '{}'", vehicle_id(), topology_->id(*vertex_));
      hold_alarm_raised_ = false;
      return true;
    }
  }
  set_activity(paused ? Activity::paused : Activity::waiting);
  pause_before_retry();
  return false;
}

void LogicalAgent::pause_before_retry() {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, kRoutePause, [&] { return stopping_.load(); });
}

void LogicalAgent::keep_standing_reserved(topology::EntityIndex vertex, DurationNs ahead) {
  const auto granted = monitor_.granted_as(vertex);
  if (!granted) return;
  RouteTracker* route = nullptr;
  if (route_ && route_->id() == granted->route) route = &*route_;
  if (remnant_ && remnant_->id() == granted->route) route = &*remnant_;
  if (route == nullptr || granted->step >= route->size() || route->step(granted->step).entity != vertex) return;
  const TimeNs end = route->step(granted->step).window.end;
  const TimeNs now = clock_.now();
  if (end == kForever || end - now > ahead / 2) return;
  // At the vertex's owner only: what follows the step is cancelled (a route given up, or
  // the rest of one being re-planned), so nothing else of the route is left to move.
  delay_at_owner(*route, granted->step, now + ahead - end);
}

bool LogicalAgent::drivable(const std::vector<topology::RouteStep>& steps) const {
  if (steps.size() % 2 == 0) return false;
  for (std::size_t i = 0; i < steps.size(); i += 2) {
    if (!topology_->is_vertex(steps[i].entity)) return false;
    if (i == 0) continue;
    const auto edge = steps[i - 1].entity;
    if (!topology_->is_edge(edge)) return false;
    const auto moves = topology_->moves_from(steps[i - 2].entity);
    const bool leads = std::any_of(moves.begin(), moves.end(), [&](const topology::Move& move) {
      return move.edge == edge && move.to == steps[i].entity;
    });
    if (!leads) return false;
  }
  return true;
}

Result<RouteTracker> LogicalAgent::plan_route(topology::EntityIndex goal, DurationNs patience, bool for_order,
                                              std::string* refusal) {
  const TimeNs give_up = clock_.now() + patience;
  bool warned = false;
  if (refusal != nullptr) refusal->clear();
  for (;;) {
    if (stopping_) return fail(ErrorCode::unavailable, "the logical agent is shutting down");
    if (for_order && order_withdrawn()) return fail(ErrorCode::not_permitted, "the order is being withdrawn");
    // Only the hold of the vertex it stands on is planned for a paused vehicle.
    if (goal != *vertex_ && pause_requested()) {
      stopped_for_pause_ = true;
      return fail(ErrorCode::not_permitted, "the vehicle is paused");
    }
    // Waiting here (a re-plan after a lock, say), the vehicle stands where its old route
    // planned to leave: the route asked for starts on that vertex now. Reserved for a
    // retry's pause and call at least, whatever the clock's factor.
    keep_standing_reserved(*vertex_, 2 * options_.delay_threshold + clock_.to_sim(2 * kRoutePause));
    take_over_late();  // what an earlier life left in a partition that is back may block this route
    topology::RouteId id = 0;
    while (id == 0) id = route_ids_();
    if (!unknown_partitions_.empty()) own_routes_.insert(id);
    msg::RouteRequest request;
    request.agent(vehicle_id());
    request.route(id);
    request.real(true);
    auto& vehicle = request.vehicle();
    vehicle.id(options_.vehicle.id);
    vehicle.type(options_.vehicle.type);
    vehicle.max_speed(options_.vehicle.max_speed);
    vehicle.acceleration(options_.vehicle.acceleration);
    vehicle.deceleration(options_.vehicle.deceleration);
    vehicle.length(options_.vehicle.length);
    vehicle.width(options_.vehicle.width);
    vehicle.payload(options_.vehicle.payload);
    request.start(topology_->id(*vertex_));
    request.start_time(clock_.now());
    msg::RouteStop stop;
    stop.vertex(topology_->id(goal));
    stop.has_dwell(false);
    request.stops().push_back(stop);

    auto reply = services_->route(request, options_.route_timeout);
    if (!reply) {
      // Nobody answered (a routing agent restarting): the route may have been reserved
      // with the reply lost, so cancel it before asking again under a new id.
      if (!warned) {
        spdlog::warn("route to '{}': {} (retrying until a routing agent answers)", topology_->id(goal),
                     reply.error().message);
        warned = true;
      }
      cancel_route_quietly(id);
      set_activity(Activity::waiting);
      pause_before_retry();
      continue;
    }
    if (auto status = dds::from_wire(reply->error()); status) {
      std::vector<topology::RouteStep> steps;
      for (const auto& step : reply->steps()) {
        const auto entity = topology_->find(step.entity());
        if (!entity) {
          cancel_route_quietly(reply->route());
          return fail(ErrorCode::not_found, "the route names '" + step.entity() + "', which topology '" +
                                                topology_->name() + "' does not have");
        }
        steps.push_back(topology::RouteStep{*entity, {step.window().start(), step.window().end()}});
      }
      if (steps.empty() || steps.front().entity != *vertex_ || steps.back().entity != goal ||
          !drivable(steps)) {
        cancel_route_quietly(reply->route());
        return fail(ErrorCode::internal, "the routing agent answered a route that does not lead from '" +
                                             topology_->id(*vertex_) + "' to '" + topology_->id(goal) +
                                             "' as vertex, edge, vertex, ... along drivable edges");
      }
      spdlog::info("route {} to '{}': {} steps, {:.1f} m, arrival in {}", reply->route(), topology_->id(goal),
                   steps.size(), reply->distance(), seconds_text(reply->arrival() - clock_.now()));
      return RouteTracker(topology_, reply->route(), std::move(steps));
    } else {
      const std::string& failure = reply->failure();
      if (refusal != nullptr) *refusal = failure;
      // A topology agent did not answer the routing agent: part of the route may be
      // reserved under this id (a commit whose reply was lost), so it is cancelled before
      // asking again under a new one.
      if (nobody_answered(status.error())) {
        cancel_route_quietly(id);
      } else {
        own_routes_.erase(id);  // refused: nothing of it is reserved anywhere
      }
      const bool blocked = failure == "no_window" || failure == "locked" || failure == "conflict" ||
                           nobody_answered(status.error());
      if (!blocked || clock_.now() >= give_up) {
        return fail(status.error().code, "no route from '" + topology_->id(*vertex_) + "' to '" +
                                             topology_->id(goal) + "': " + status.error().message);
      }
      if (!warned) {
        spdlog::info("no route to '{}' yet ({}): retrying", topology_->id(goal), status.error().message);
        warned = true;
      }
      ask_make_way({reply->blockers().begin(), reply->blockers().end()}, goal);
      // Waiting here, the vehicle may itself stand in another's way (two vehicles that want
      // each other's place): it drives aside, then plans from there.
      if (!making_way_) {
        if (auto requester = make_way_requested(); requester && make_way(*requester)) continue;
      }
      set_activity(Activity::waiting);
      pause_before_retry();
    }
  }
}

Status LogicalAgent::switch_route(RouteTracker next) {
  const auto here = next.step(0).entity;
  // The vehicle holds `here` under the previous route: hand the allocation over to the new
  // route's first step (nobody can come between: the new reservation starts now and the
  // old one held the vertex since the vehicle arrived).
  if (monitor_.holds(here)) {
    if (auto released = services_->release(vehicle_id(), here, monitor_.granted_as(here)); !released) {
      cancel_route_quietly(next);  // nothing was handed over: the new route must not stay reserved
      return released;
    }
    monitor_.drop(here);
  }
  for (;;) {
    if (stopping_) return fail(ErrorCode::unavailable, "the logical agent is shutting down");
    auto outcome = services_->allocate(vehicle_id(), here, options_.allocate_wait);
    if (!outcome) {
      // The new route will not be driven: what is left of its reservation (up to its goal,
      // held open-ended) must not block others. Not so on shutdown above: the vertex the
      // vehicle stands on is held by nothing else now, and the next life takes over.
      cancel_route_quietly(next);
      return unexpected(outcome.error());
    }
    if (outcome->granted) break;
    // Not granted at once (its owner restarting, say): ask again after a tick, not in a
    // busy loop; a long wait is told to the operator as any wait for an allocation is.
    note_allocation_wait(here);
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, options_.tick, [&] { return stopping_.load(); });
  }
  if (route_ && route_->id() != next.id()) cancel_route_quietly(*route_);
  remnant_.reset();  // what it held of the vertex is handed over above; the rest is passed
  if (next.size() > 1) {
    std::lock_guard lock(mutex_);
    make_way_.reset();  // the vehicle leaves anyway
  }
  end_allocation_wait();
  monitor_.forget_steps();
  monitor_.hold(here, HeldStep{next.id(), 0});
  next.mark_allocated();
  route_ = std::move(next);
  pending_moves_.clear();
  own_shift_echoes_.clear();
  return {};
}

Status LogicalAgent::drive_to(topology::EntityIndex goal, Activity activity, DurationNs patience,
                              std::optional<RouteTracker> planned) {
  drive_activity_ = activity;
  for (;;) {
    if (route_ && route_->arrived() && vertex_ == goal) return {};
    set_activity(activity);
    Result<RouteTracker> route =
        planned ? Result<RouteTracker>(std::move(*planned)) : plan_route(goal, patience, activity == Activity::driving);
    planned.reset();
    if (!route) {
      // Stranded half-way (a re-plan found nothing): the rest of the old route must not
      // keep blocking others.
      if (route_ && !route_->arrived()) abandon_route();
      return unexpected(route.error());
    }
    if (auto switched = switch_route(std::move(*route)); !switched) {
      if (route_ && !route_->arrived()) abandon_route();  // as above: hold_position takes over
      return switched;
    }
    std::string failure;
    const FollowResult result = follow(failure);
    switch (result) {
      case FollowResult::arrived:
        vertex_ = goal;
        return {};
      case FollowResult::replan:
        spdlog::info("re-planning from '{}'", topology_->id(*vertex_));
        // The rest of the route goes now, but for what the vehicle holds: those due after it
        // there need not wait for it, and while it waits for a new route only the vertex it
        // stands on is kept reserved (keep_standing_reserved).
        cancel_route_quietly(*route_);
        continue;
      case FollowResult::failed:
        abandon_route();
        return fail(ErrorCode::unavailable, failure);
      case FollowResult::withdrawn:
      case FollowResult::paused:
        // The vehicle stands on the vertex its last move reached: the rest of the route goes
        // (paused: the drive is asked for again once the vehicle is resumed).
        abandon_route();
        if (result == FollowResult::withdrawn) return fail(ErrorCode::not_permitted, "the order is being withdrawn");
        stopped_for_pause_ = true;
        return fail(ErrorCode::not_permitted, "the vehicle is paused");
    }
  }
}

CommandWatch LogicalAgent::watch_from_now() {
  // A status lists a command it accepted at once; one still missing after the time a RAN
  // may be silent was not a late status.
  return CommandWatch(std::chrono::steady_clock::now(), kRanSilence);
}

std::optional<std::string> LogicalAgent::lost_move() {
  for (auto& move : pending_moves_) {
    if (ended_commands_.contains(move.id)) continue;
    if (const auto loss = move.watch.observe(*status_, move.id, status_received_); loss != CommandWatch::Loss::none) {
      return fmt::format("the move to '{}' {}: the vehicle stands where the RAN left it",
                         topology_->id(route_->step(move.target).entity), loss_text(loss));
    }
  }
  return std::nullopt;
}

LogicalAgent::FollowResult LogicalAgent::follow(std::string& failure) {
  bool replan = false;
  for (;;) {
    if (stopping_) {
      failure = "the logical agent is shutting down";
      return FollowResult::failed;
    }
    process_notices(replan);
    // Moves the RAN ended, in order.
    {
      std::unique_lock lock(mutex_);
      while (!pending_moves_.empty()) {
        const auto& [id, target, watch] = pending_moves_.front();
        const auto ended = ended_commands_.find(id);
        if (ended == ended_commands_.end()) break;
        if (ended->second.state != ran::CommandState::finished) {
          failure = fmt::format("move to '{}' {}: {} {}", topology_->id(route_->step(target).entity),
                                ran::to_string(ended->second.state), ended->second.code, ended->second.reason);
          lock.unlock();
          // A move fails when the vehicle breaks down: that is critical, as check_errors says.
          const auto status = latest_status();
          const bool fatal = status && std::any_of(status->errors.begin(), status->errors.end(), [](const auto& e) {
                               return e.level == ran::ErrorLevel::fatal;
                             });
          raise_alarm(fatal ? msg::ALARM_CRITICAL : msg::ALARM_ERROR, "vehicle '" + vehicle_id() + "': " + failure);
          critical_stop_ = critical_stop_ || fatal;
          stop_vehicle();
          return FollowResult::failed;
        }
        route_->mark_reached(target);
        vertex_ = route_->step(target).entity;
        ended_commands_.erase(ended);
        pending_moves_.pop_front();
      }
      // Checked with the ends above under one lock: a status that ends a move records its
      // end before it is the latest.
      if (auto lost = status_ ? lost_move() : std::nullopt) {
        failure = std::move(*lost);
        lock.unlock();
        raise_alarm(msg::ALARM_ERROR, "vehicle '" + vehicle_id() + "': " + failure);
        stop_vehicle();
        return FollowResult::failed;
      }
    }
    const auto status = latest_status();
    if (status) {
      if (!monitor_.inside(status->footprint)) {
        stop_vehicle();
        failure = fmt::format("the footprint of vehicle '{}' left its allocated area near ({:.2f}, {:.2f}) by {:.3f} m^2",
                              vehicle_id(), status->pose.x, status->pose.y, monitor_.area_outside(status->footprint));
        raise_alarm(msg::ALARM_CRITICAL, failure);
        critical_stop_ = true;
        return FollowResult::failed;
      }
      if (auto error = check_errors(*status)) {
        stop_vehicle();
        failure = *error;
        return FollowResult::failed;
      }
      release_passed(*status);
      const topology::Point position(status->pose.x, status->pose.y);
      if (auto late = route_->lateness(position, status->linear_speed, options_.vehicle, clock_.now());
          late && *late > options_.delay_threshold) {
        propagate_delay(*route_, route_->position_step(), *late + options_.delay_threshold);
      }
    }
    if (route_->arrived() && pending_moves_.empty()) return FollowResult::arrived;
    // A withdrawal, like a re-plan, allocates nothing more: the vehicle drives the moves it
    // was given (at most the look-ahead) and stands on a vertex, never part-way along an
    // edge as a cancel would leave it.
    const bool withdrawn = drive_activity_ == Activity::driving && order_withdrawn();
    const bool paused = !withdrawn && pause_requested();
    if (replan || withdrawn || paused) {
      if (pending_moves_.empty()) {
        return withdrawn ? FollowResult::withdrawn : paused ? FollowResult::paused : FollowResult::replan;
      }
    } else {
      // Allocation ahead, in route order, within the look-ahead.
      while (auto next = route_->next_to_allocate(route_->position_step(), options_.lookahead)) {
        const auto entity = route_->step(*next).entity;
        // A route may come back to an entity the vehicle still holds from an earlier step
        // (it stepped aside to let another pass). That is a later reservation: it is asked
        // for only once the earlier one is released, so it waits its turn behind whoever
        // passes in between (asking now would only report the holding we have).
        if (monitor_.holds(entity)) break;
        auto outcome = services_->allocate(vehicle_id(), entity, options_.allocate_wait);
        if (!outcome) {
          // Our reservation there is gone (cancelled, or the topology agent lost it): the
          // rest of the route is no longer ours.
          spdlog::warn("allocation of '{}' refused: {}", topology_->id(entity), outcome.error().message);
          replan = true;
          break;
        }
        if (!outcome->granted) {
          note_allocation_wait(entity);
          break;
        }
        end_allocation_wait();
        monitor_.hold(entity, HeldStep{route_->id(), static_cast<std::uint32_t>(*next)});
        route_->mark_allocated();
      }
      // Moves up to the last allocated vertex.
      while (auto edge = route_->next_move()) {
        const auto move = route_->command_move(*edge, next_command_id(), options_.vehicle.max_speed);
        auto verdict = ran_->move(move, options_.call_timeout);
        if (!verdict || verdict->rejected()) {
          failure = verdict ? fmt::format("the RAN rejected the move to '{}': {} {}", move.target_vertex,
                                          verdict->code, verdict->reason)
                            : "the RAN did not take the move to '" + move.target_vertex + "': " + verdict.error().message;
          raise_alarm(msg::ALARM_ERROR, "vehicle '" + vehicle_id() + "': " + failure);
          // Unanswered, the RAN may still have taken the move: cancel it with the others.
          if (!verdict) pending_moves_.push_back(PendingMove{move.id, *edge + 1, watch_from_now()});
          stop_vehicle();
          return FollowResult::failed;
        }
        pending_moves_.push_back(PendingMove{move.id, *edge + 1, watch_from_now()});
      }
    }
    set_activity(error_since_ || pending_moves_.empty() ? Activity::waiting : drive_activity_);
    publish_vehicle_state(false);
    wait_event();
  }
}

void LogicalAgent::note_allocation_wait(topology::EntityIndex entity) {
  const TimeNs now = clock_.now();
  if (!allocation_wait_ || allocation_wait_->entity != entity) allocation_wait_ = AllocationWait{entity, now, false};
  if (allocation_wait_->told || options_.wait_alarm <= 0 || now - allocation_wait_->since < options_.wait_alarm) return;
  const auto& id = topology_->id(entity);
  // The reply does not say why (a vehicle due there first that does not move on, a lock, an
  // owner out of reach): the timeline does.
  raise_alarm(msg::ALARM_WARNING, fmt::format("vehicle '{}' has waited {} for '{}' ('droverctl timeline {}' shows "
                                              "who holds it, who comes first and its locks)",
                                              vehicle_id(), seconds_text(now - allocation_wait_->since), id, id));
  allocation_wait_->told = true;
}

void LogicalAgent::end_allocation_wait() {
  if (allocation_wait_ && allocation_wait_->told) {
    spdlog::info("the wait for '{}' is over after {}", topology_->id(allocation_wait_->entity),
                 seconds_text(clock_.now() - allocation_wait_->since));
  }
  allocation_wait_.reset();
}

void LogicalAgent::release_passed(const ran::VehicleStatus& status) {
  for (const auto entity : monitor_.releasable(status.footprint, route_ ? route_->reached() : 0)) {
    if (entity == driving_onto_) continue;  // not reached yet
    if (auto released = services_->release(vehicle_id(), entity, monitor_.granted_as(entity)); !released) {
      spdlog::warn("release of '{}' failed: {}", topology_->id(entity), released.error().message);
      continue;
    }
    monitor_.drop(entity);
  }
}

std::optional<std::string> LogicalAgent::check_errors(const ran::VehicleStatus& status) {
  // Both RANs take what is sent to the vehicle's RAN: nothing more goes out but the cancel
  // of what runs (the alarm went out when their statuses began to be refused).
  if (ran_->two_rans()) return "two RANs report for vehicle '" + vehicle_id() + "'; stop the one that does not drive it";
  const ran::VehicleError* fatal = nullptr;
  const ran::VehicleError* recoverable = nullptr;
  for (const auto& error : status.errors) {
    if (error.level == ran::ErrorLevel::fatal && fatal == nullptr) fatal = &error;
    if (error.level == ran::ErrorLevel::recoverable && recoverable == nullptr) recoverable = &error;
  }
  if (fatal != nullptr) {
    const std::string reason = "unrecoverable RAN error " + fatal->code + ": " + fatal->text;
    raise_alarm(msg::ALARM_CRITICAL, "vehicle '" + vehicle_id() + "': " + reason);
    critical_stop_ = true;
    return reason;
  }
  std::string cause;
  if (recoverable != nullptr) {
    cause = recoverable->code + ": " + recoverable->text;
  } else {
    std::lock_guard lock(mutex_);
    if (std::chrono::steady_clock::now() - status_received_ > kRanSilence) cause = silence_cause();
  }
  if (cause.empty()) {
    if (error_since_) spdlog::info("RAN error over after {}", seconds_text(clock_.now() - *error_since_));
    error_since_.reset();
    return std::nullopt;
  }
  const TimeNs now = clock_.now();
  if (!error_since_) {
    spdlog::warn("recoverable RAN error {}: waiting it out", cause);
    error_since_ = now;
  } else if (now - *error_since_ > options_.error_limit) {
    const std::string reason = "recoverable RAN error " + cause + " lasted longer than " + seconds_text(options_.error_limit);
    raise_alarm(msg::ALARM_ERROR, "vehicle '" + vehicle_id() + "': " + reason);
    error_since_.reset();
    return reason;
  }
  return std::nullopt;
}

std::string LogicalAgent::silence_cause() const {
  const auto refusal = ran_->refusal(kRanSilence);
  return refusal ? "ran_status_refused: " + *refusal : "ran_lost: no status from the RAN";
}

bool LogicalAgent::delay_at_owner(RouteTracker& route, std::size_t from_step, DurationNs by) {
  const auto entity = route.step(from_step).entity;
  auto shifts = services_->delay(vehicle_id(), route.id(), entity, by);
  if (!shifts) {
    spdlog::warn("delay of {} at '{}' not propagated: {}", seconds_text(by), topology_->id(entity),
                 shifts.error().message);
    return false;
  }
  for (const auto& shift : *shifts) {
    if (shift.agent == vehicle_id() && shift.route == route.id()) {
      route.shift(shift.from_step, shift.by);
      own_shift_echoes_.insert({shift.route, shift.by});
    }
  }
  spdlog::info("delay of {} propagated from '{}' (step {}): {} route(s) moved", seconds_text(by),
               topology_->id(entity), from_step, shifts->size());
  return true;
}

void LogicalAgent::propagate_delay(RouteTracker& route, std::size_t from_step, DurationNs by) {
  if (!delay_at_owner(route, from_step, by)) return;
  // The owners of the rest of the route's partitions move their part too.
  const auto entity = route.step(from_step).entity;
  std::set<std::string> partitions{topology_->partition(entity)};
  for (std::size_t step = from_step + 1; step < route.size(); ++step) {
    const auto other = route.step(step).entity;
    if (!partitions.insert(topology_->partition(other)).second) continue;
    auto more = services_->delay(vehicle_id(), route.id(), other, by);
    if (!more) continue;
    for (const auto& shift : *more) {
      if (shift.agent == vehicle_id() && shift.route == route.id()) own_shift_echoes_.insert({shift.route, shift.by});
    }
  }
}

void LogicalAgent::process_notices(bool& replan) {
  std::deque<msg::ReservationNotice> batch;
  {
    std::lock_guard lock(mutex_);
    batch.swap(notices_);
  }
  for (const auto& notice : batch) {
    if (notice.kind() == msg::NOTICE_ALLOCATION_GRANTED) {
      // Claimed by the allocate reply, usually: only the grants it missed matter.
      const auto entity = topology_->find(notice.entity());
      if (entity && !monitor_.holds(*entity)) {
        late_grants_.granted(*entity, HeldStep{notice.route(), notice.from_step()}, std::chrono::steady_clock::now());
      }
      continue;
    }
    if (!route_ || notice.route() != route_->id()) continue;
    if (notice.kind() == msg::NOTICE_SHIFTED) {
      const auto echo = own_shift_echoes_.find({notice.route(), notice.shift()});
      if (echo != own_shift_echoes_.end()) {
        own_shift_echoes_.erase(echo);
        continue;
      }
      route_->shift(notice.from_step(), notice.shift());
      spdlog::info("following a delay: route {} moved by {} from step {} ('{}' delayed at '{}')", notice.route(),
                   seconds_text(notice.shift()), notice.from_step(), notice.source(), notice.entity());
      // Parts of the route other topology agents own move too.
      const auto source_partitions = services_->partitions_of(notice.source());
      std::set<std::string> partitions(source_partitions.begin(), source_partitions.end());
      for (std::size_t step = notice.from_step(); step < route_->size(); ++step) {
        const auto entity = route_->step(step).entity;
        if (!partitions.insert(topology_->partition(entity)).second) continue;
        auto more = services_->delay(vehicle_id(), route_->id(), entity, notice.shift());
        if (!more) continue;
        for (const auto& shift : *more) {
          if (shift.agent == vehicle_id() && shift.route == route_->id()) {
            own_shift_echoes_.insert({shift.route, shift.by});
          }
        }
      }
    } else if (notice.kind() == msg::NOTICE_LOCK_HIT) {
      const auto locked = topology_->find(notice.entity());
      if (!locked) continue;
      for (std::size_t step = route_->allocated(); step < route_->size(); ++step) {
        const auto entity = route_->step(step).entity;
        const auto conflicts = topology_->conflicts(entity);
        if (entity == *locked || std::find(conflicts.begin(), conflicts.end(), *locked) != conflicts.end()) {
          spdlog::info("lock {} on '{}' hits route {} at step {}: re-planning", notice.lock_id(), notice.entity(),
                       route_->id(), step);
          replan = true;
          break;
        }
      }
    }
  }
  give_back_late_grants();
}

void LogicalAgent::give_back_late_grants() {
  if (late_grants_.empty()) return;
  const auto claimed = [this](topology::EntityIndex entity) { return monitor_.holds(entity); };
  const auto current = route_ ? std::optional<topology::RouteId>(route_->id()) : std::nullopt;
  for (const auto& [entity, step] : late_grants_.to_release(claimed, current, std::chrono::steady_clock::now())) {
    // Not under the vehicle: moves go only onto what an allocate reply granted.
    if (auto released = services_->release(vehicle_id(), entity, step); !released) {
      spdlog::warn("'{}', granted after its request was given up, not released: {}", topology_->id(entity),
                   released.error().message);
    } else {
      spdlog::info("'{}' was granted after its request was given up (route {} step {}): released", topology_->id(entity),
                   step.route, step.step);
    }
  }
}

bool LogicalAgent::stop_vehicle() {
  // The moves the RAN has not reported ended, oldest first: a cancel ends the move it names
  // and every one queued after it, but the RAN refuses to cancel a move that has ended (the
  // report may be on its way), and its reply does not say so: each is cancelled in turn (a
  // cancel of one ended by an earlier cancel is refused alike, and harmless).
  std::vector<ran::CommandId> unended;
  {
    std::lock_guard lock(mutex_);
    for (const auto& move : pending_moves_) {
      if (!ended_commands_.contains(move.id)) unended.push_back(move.id);
    }
  }
  if (!unended.empty()) {
    bool delivered = false;
    for (const auto& id : unended) {
      auto cancelled = ran_->cancel(id, options_.call_timeout);
      if (cancelled) {
        delivered = true;
        continue;
      }
      if (nobody_answered(cancelled.error())) {  // the RAN is out of reach: said once
        if (!stop_undelivered_) spdlog::warn("cancel of move '{}' not delivered: {}", id, cancelled.error().message);
        stop_undelivered_ = true;
        delivered = false;  // the moves after it may run on
        break;
      }
      spdlog::info("cancel of move '{}' not taken: {}", id, cancelled.error().message);
    }
    if (!delivered) return false;  // the moves stay pending: the next call cancels them
    stop_undelivered_ = false;
    stop_asked_ = clock_.now();
  }
  pending_moves_.clear();
  if (!stop_asked_) return true;  // every move ended: nothing was cancelled
  // A cancelled vehicle brakes into what it was allowed onto: nothing may be released
  // before it stands, so wait (bounded) for a status after the cancel that shows it still.
  std::unique_lock lock(mutex_);
  if (!wake_.wait_for(lock, kStopWait, [&] { return stopping_ || fresh_and_standing(*stop_asked_); }) ||
      !fresh_and_standing(*stop_asked_)) {
    spdlog::warn("vehicle '{}' did not report standing still after the cancel", vehicle_id());
    return false;  // asked again by the next call
  }
  stop_asked_.reset();
  return true;
}

const ran::VehicleStatus* LogicalAgent::heard_status() const {
  if (!status_ || std::chrono::steady_clock::now() - status_received_ > kRanSilence || ran_->refusal(kRanSilence)) {
    return nullptr;
  }
  return &*status_;
}

bool LogicalAgent::fresh_and_standing(TimeNs since) const {
  return status_ && status_->time > since && ran::standing_still(status_->linear_speed, status_->angular_speed);
}

void LogicalAgent::cancel_route_quietly(topology::RouteId route) {
  if (auto cancelled = services_->cancel_route(vehicle_id(), route, monitor_.held_steps_of(route)); !cancelled) {
    spdlog::warn("route {} not cancelled: {}", route, cancelled.error().message);
  }
}

void LogicalAgent::cancel_route_quietly(const RouteTracker& route) {
  if (auto cancelled = services_->cancel_route(vehicle_id(), route.id(), monitor_.held_steps_of(route.id()),
                                               services_->partitions_touched(route.steps()));
      !cancelled) {
    spdlog::warn("route {} not cancelled: {}", route.id(), cancelled.error().message);
  }
}

void LogicalAgent::abandon_route() {
  if (!route_) return;
  const bool stands = stop_vehicle();  // before anything is released
  // The steps the vehicle holds stay reserved; the rest of the route goes.
  cancel_route_quietly(*route_);
  monitor_.forget_steps();
  if (const auto status = latest_status(); status && stands) {
    for (const auto entity : monitor_.releasable(status->footprint, 0)) {
      if (services_->release(vehicle_id(), entity, monitor_.granted_as(entity))) monitor_.drop(entity);
    }
  } else {
    // Where the vehicle is, or whether it still rolls, is unknown: it keeps everything it
    // was allowed onto until hold_position sees it stand again.
    spdlog::warn("vehicle '{}' not known to stand: keeping its {} allocation(s)", vehicle_id(), monitor_.held().size());
  }
  remnant_ = std::move(route_);
  route_.reset();
}

Status LogicalAgent::operate(const ran::ActionCommand& requested, Activity activity, bool for_order) {
  set_activity(activity);
  ran::ActionCommand action = requested;
  action.id = next_command_id();
  if (for_order) {
    // Recorded before it is sent: an agent restarted after the RAN got it must not do it again.
    std::lock_guard lock(mutex_);
    if (Status recorded = book_.action_commanded(action.id); !recorded) {
      return fail(recorded.error().code, "action '" + action.name + "' not commanded, since a restart would not know "
                                         "of it: " + recorded.error().message);
    }
  }
  auto verdict = ran_->action(action, options_.call_timeout);
  if (!verdict) return fail(verdict.error().code, "the RAN did not take action '" + action.name + "': " + verdict.error().message);
  if (verdict->rejected()) {
    return fail(ErrorCode::not_permitted, "the RAN rejected action '" + action.name + "': " + verdict->code + " " + verdict->reason);
  }
  return await_action(action.id, action.name, watch_from_now());
}

Status LogicalAgent::await_action(const ran::CommandId& command, const std::string& name,
                                  CommandWatch watch) {
  for (;;) {
    if (!wait_event()) return fail(ErrorCode::unavailable, "the logical agent is shutting down");
    bool replan = false;
    process_notices(replan);
    std::optional<ran::CommandProgress> ended;
    std::optional<ran::VehicleStatus> status;
    CommandWatch::Clock::time_point received;
    {
      // Both at once: a status that ends the command records its end before it is the latest.
      std::lock_guard lock(mutex_);
      if (auto found = ended_commands_.find(command); found != ended_commands_.end()) {
        ended = found->second;
        ended_commands_.erase(found);
      }
      status = status_;
      received = status_received_;
    }
    if (ended) {
      if (ended->state == ran::CommandState::finished) return {};
      return fail(ErrorCode::unavailable, "action '" + name + "' " + ran::to_string(ended->state) + ": " +
                                              ended->code + " " + ended->reason);
    }
    if (status) {
      if (const auto loss = watch.observe(*status, command, received); loss != CommandWatch::Loss::none) {
        return fail(ErrorCode::unavailable, "action '" + name + "' (RAN command '" + command + "') " +
                                                loss_text(loss) + ": whether it was done is unknown (check the vehicle)");
      }
      if (auto error = check_errors(*status)) {
        if (auto cancelled = ran_->cancel(command, options_.call_timeout); !cancelled) {
          spdlog::warn("cancel of action '{}' not delivered: {}", name, cancelled.error().message);
        }
        return fail(ErrorCode::unavailable, *error);
      }
    }
    publish_vehicle_state(false);
  }
}

bool LogicalAgent::order_withdrawn() {
  std::lock_guard lock(mutex_);
  return book_.withdrawal_pending();
}

bool LogicalAgent::pause_requested() {
  std::lock_guard lock(mutex_);
  return pause_.has_value();
}

bool LogicalAgent::adopted_action_pending() {
  std::lock_guard lock(mutex_);
  return adopted_command_.has_value();
}

bool LogicalAgent::end_pending_withdrawal() {
  std::lock_guard lock(mutex_);
  if (!book_.withdrawal_pending()) return false;
  spdlog::info("order '{}' withdrawn", book_.current()->name);
  book_.end_withdrawn(clock_.now());
  return true;
}

void LogicalAgent::execute_order() {
  // A withdrawal ends the order between its steps: before a drive, after it (the operation
  // is skipped), or after an operation (which is completed, not cut short) when more
  // destinations follow; a drive under way stops at the next vertex it can (drive_to).
  // A pause leaves the order running where it got to: the run loop holds the vertex the
  // vehicle stands on and comes back here once it is resumed.
  const auto paused_at = [this](const std::string& name) {
    if (!pause_requested()) return false;
    spdlog::info("order '{}' waits: the vehicle is paused", name);
    return true;
  };
  const auto stopped_for_pause = [this](const std::string& name) {
    if (!std::exchange(stopped_for_pause_, false)) return false;
    spdlog::info("order '{}' waits: the vehicle was paused on the way", name);
    return true;
  };
  for (;;) {
    Destination destination;
    std::string name;
    bool last = false;
    std::optional<ran::CommandId> commanded;  // by an earlier life: the order was restored
    Status performed;
    {
      std::lock_guard lock(mutex_);
      const Order* order = book_.current();
      if (order == nullptr) return;
      destination = order->destinations[order->destination];
      name = order->name;
      last = order->destination + 1 == order->destinations.size();
      commanded = order->action_command;
      // An order queued before the RAN was heard, or restored from the journal, was not
      // checked against what the vehicle performs: it fails before the drive, not after it.
      if (const auto* status = heard_status(); status && !commanded) {
        performed = check_operations(*order, *status, order->destination);
      }
    }
    Status done;
    if (commanded) {
      done = resume_action(*commanded, destination);  // an operation under way is completed first
    } else if (!performed) {
      done = std::move(performed);
    } else {
      if (end_pending_withdrawal() || paused_at(name)) return;
      stopped_for_pause_ = false;
      done = drive_to(destination.location, Activity::driving, options_.route_limit);
      if (end_pending_withdrawal()) return;
      if (!done && stopped_for_pause(name)) return;  // the drive is asked for again once resumed
      if (done) {
        if (auto action = operation_action(destination)) {
          if (paused_at(name)) return;  // not begun: the drive to here finds it arrived
          const bool charge = action->kind == ran::ActionKind::charge;
          if (charge && !action->parameters.count("target")) action->parameters["target"] = std::to_string(options_.charge_to);
          done = operate(*action, charge ? Activity::charging : Activity::operating, true);
        }
      }
    }
    if (done && !last && end_pending_withdrawal()) return;
    if (!done) {
      if (stopping_ && journal_) {
        // Stopped, not failed: the journal has it running (with its action, if commanded),
        // and the next life goes on with it.
        spdlog::info("order '{}' stays running in the order journal for the next life", name);
        return;
      }
      if (!stopping_) {
        raise_alarm(msg::ALARM_ERROR, "order '" + name + "' of vehicle '" + vehicle_id() + "' failed: " + done.error().message);
      }
      std::lock_guard lock(mutex_);
      book_.fail_current(done.error().message, clock_.now());
      return;
    }
    std::lock_guard lock(mutex_);
    if (!book_.advance(clock_.now())) return;
  }
}

bool LogicalAgent::drive_to_nearest(topology::VertexKind kind, bool here_will_do) {
  stopped_for_pause_ = false;  // this search's own stop, for its caller to read
  if (here_will_do && topology_->vertex(*vertex_).kind == kind) return true;
  const auto here = topology_->vertex(*vertex_).position;
  std::vector<topology::EntityIndex> candidates;
  for (topology::EntityIndex v = 0; v < topology_->vertex_count(); ++v) {
    if (topology_->vertex(v).kind == kind && v != *vertex_) candidates.push_back(v);
  }
  std::sort(candidates.begin(), candidates.end(), [&](auto a, auto b) {
    return bg::distance(here, topology_->vertex(a).position) < bg::distance(here, topology_->vertex(b).position);
  });
  const bool charger = kind == topology::VertexKind::charger;
  const Activity activity = charger ? Activity::charging : Activity::parking;
  for (const auto candidate : candidates) {
    if (stopping_) break;
    spdlog::info("{}: trying '{}'", charger ? "going to charge" : "parking", topology_->id(candidate));
    auto route = plan_route(candidate, 0, false);
    if (!route && stopped_for_pause_) return false;  // refused for the pause: so would every other be
    if (!route) {
      spdlog::info("no route to '{}' now: {}", topology_->id(candidate), route.error().message);
      continue;
    }
    const auto driven = drive_to(candidate, activity, 0, std::move(*route));
    if (driven) return true;
    // On the way: an alarm said why, or a re-plan found nothing.
    spdlog::info("'{}' not reached: {}", topology_->id(candidate), driven.error().message);
    return false;
  }
  return false;
}

void LogicalAgent::go_to_service_vertex(topology::VertexKind kind) {
  const bool charger = kind == topology::VertexKind::charger;
  const bool reached = drive_to_nearest(kind, true);
  idle_since_ = clock_.now();
  // Stopped for the pause, not failed, or reached just as the pause came: nothing is begun
  // (no charge), and it is tried again once the vehicle is resumed.
  if (std::exchange(stopped_for_pause_, false) || pause_requested()) return;
  if (!reached) {
    if (charger) charge_retry_at_ = clock_.now() + kChargeRetry;
    spdlog::warn("no {} vertex could be reached", charger ? "charger" : "parking");
    return;
  }
  if (charger) {
    ran::ActionCommand charge;
    charge.kind = ran::ActionKind::charge;
    charge.name = "charge";
    charge.parameters["target"] = std::to_string(options_.charge_to);
    if (auto charged = operate(charge, Activity::charging); !charged) {
      charge_retry_at_ = clock_.now() + kChargeRetry;
      raise_alarm(msg::ALARM_WARNING, "vehicle '" + vehicle_id() + "' could not charge: " + charged.error().message);
    } else if (const auto status = latest_status();
               status && status->battery.state_of_charge < options_.charge_below) {
      // The charge ended where another would start at once (a charger that does not
      // deliver): not again before the retry time, so that orders run meanwhile.
      charge_retry_at_ = clock_.now() + kChargeRetry;
      raise_alarm(msg::ALARM_WARNING,
                  fmt::format("vehicle '{}' charged to {:.2f} only, under the threshold {:.2f}", vehicle_id(),
                              status->battery.state_of_charge, options_.charge_below));
    }
  }
}

}  // namespace drover::logical_agent

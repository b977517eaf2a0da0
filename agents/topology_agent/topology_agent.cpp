#include "agents/topology_agent/topology_agent.hpp"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <set>
#include <tuple>

#include <spdlog/spdlog.h>

#include "agents/topology_agent/wire.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/dds/wire_error.hpp"

namespace drover::topology_agent {

namespace {

/// A prepared hold lives at most this long (shared clock): one expiring later is refused.
/// The routing agents hold for seconds (--prepare-ttl); a later expiry means another clock
/// (--epoch, --time-factor), and a hold whose routing agent died would block others for good.
constexpr DurationNs kLongestHold = 3600 * kNsPerSecond;
/// One delay moves a route at most this far: more is a unit mix-up (s for ns), which would
/// push the route and every one behind it for years.
constexpr DurationNs kLongestDelay = 24 * 3600 * kNsPerSecond;

/// Sends a reply and logs when it could not go out (the requester went away).
template <class Rep>
void send_reply(dds::ReplyHandle<Rep>& handle, Rep reply) {
  if (auto sent = handle.send(std::move(reply)); !sent) {
    spdlog::warn("reply to '{}' not sent: {}", handle.requester(), sent.error().message);
  }
}

template <class Rep>
void send_error(dds::ReplyHandle<Rep>& handle, const Error& error) {
  spdlog::info("request of '{}' rejected: {}", handle.requester(), error.message);
  if (auto sent = handle.send_error(error); !sent) {
    spdlog::warn("error reply to '{}' not sent: {}", handle.requester(), sent.error().message);
  }
}

void send_status(dds::ReplyHandle<msg::StatusReply>& handle, const Status& status) {
  if (!status) return send_error(handle, status.error());
  send_reply(handle, msg::StatusReply{});
}

/// The real reservation of (agent, route, step) on `timeline`, if it is there.
std::optional<topology::Reservation> find_real(const topology::Timeline& timeline, const std::string& agent,
                                               topology::RouteId route, std::uint32_t step) {
  for (const auto& item : timeline.reservations) {
    if (!item.shadow() && item.agent == agent && item.route == route && item.step == step) return item;
  }
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<TopologyAgent>> TopologyAgent::create(topology::Topology topology,
                                                             SharedClock clock,
                                                             TopologyAgentOptions options) {
  std::vector<bool> owned(topology.entity_count(), options.partition.empty());
  std::size_t owned_count = options.partition.empty() ? topology.entity_count() : 0;
  if (!options.partition.empty()) {
    for (topology::EntityIndex entity = 0; entity < topology.entity_count(); ++entity) {
      if (topology.partition(entity) != options.partition) continue;
      owned[entity] = true;
      ++owned_count;
    }
  }
  if (owned_count == 0) {
    std::string known;
    for (const auto& name : topology.partitions()) known += (known.empty() ? "" : ", ") + name;
    return fail(ErrorCode::invalid_argument,
                options.partition.empty()
                    ? "topology '" + topology.name() + "' has no entity"
                    : "partition '" + options.partition + "' owns no entity of topology '" +
                          topology.name() + "' (its partitions: " + known + ")");
  }
  std::optional<Journal> journal;
  std::optional<topology::TimelineSet> timelines;
  if (options.journal_file.empty()) {
    timelines.emplace(topology.conflict_sets(), std::move(owned));
  } else {
    auto opened = Journal::open(options.journal_file, journal_key(topology, options.partition));
    if (!opened) return unexpected(opened.error());
    journal.emplace(std::move(*opened));
    auto restored = restore_timelines(*journal, topology.conflict_sets(), std::move(owned));
    if (!restored) return unexpected(restored.error());
    timelines.emplace(std::move(*restored));
  }
  auto participant = dds::Participant::create(options.participant);
  if (!participant) return unexpected(participant.error());
  std::unique_ptr<TopologyAgent> agent(new TopologyAgent(std::move(topology), clock, std::move(options),
                                                         owned_count, std::move(*timelines),
                                                         std::move(journal), std::move(*participant)));
  if (auto started = agent->start(); !started) return unexpected(started.error());
  return agent;
}

TopologyAgent::TopologyAgent(topology::Topology topology, SharedClock clock, TopologyAgentOptions options,
                             std::size_t owned_count, topology::TimelineSet timelines,
                             std::optional<Journal> journal, std::unique_ptr<dds::Participant> participant)
    : topology_(std::move(topology)),
      clock_(clock),
      options_(std::move(options)),
      owned_count_(owned_count),
      participant_(std::move(participant)),
      timelines_(std::move(timelines)),
      journal_(std::move(journal)),
      published_versions_(topology_.entity_count(), 0) {
  // A queued request is granted when what stood before it goes (release, cancel, commit,
  // abort, expiry): by the same lock rule as a request that arrives (on_allocate). Called
  // by the set under mutex_.
  timelines_.set_grant_filter([this](const topology::AgentId& agent, topology::EntityIndex entity) {
    return first_step_of_route(entity, agent) || !locked_now(entity);
  });
}

std::vector<std::string> TopologyAgent::served_partitions() const {
  if (!options_.partition.empty()) return {options_.partition};
  return topology_.partitions();
}

Status TopologyAgent::start() {
  auto descriptions = dds::Writer<msg::EntityDescription>::create(*participant_, kEntityTopic);
  if (!descriptions) return unexpected(descriptions.error());
  description_writer_ = std::move(*descriptions);
  auto timelines = dds::Writer<msg::TimelineState>::create(*participant_, kTimelineTopic);
  if (!timelines) return unexpected(timelines.error());
  timeline_writer_ = std::move(*timelines);
  auto notices = dds::Writer<msg::ReservationNotice>::create(*participant_, kNoticeTopic,
                                                             dds::TopicQos::events());
  if (!notices) return unexpected(notices.error());
  notice_writer_ = std::move(*notices);
  auto events = dds::Writer<msg::TopologyEvent>::create(*participant_, kEventTopic, dds::TopicQos::events());
  if (!events) return unexpected(events.error());
  event_writer_ = std::move(*events);

  {
    std::lock_guard lock(mutex_);
    for (topology::EntityIndex entity = 0; entity < topology_.entity_count(); ++entity) {
      if (!timelines_.owns(entity)) continue;
      if (auto written = description_writer_->write(to_wire_description(topology_, entity)); !written) {
        return unexpected(written.error());
      }
      const auto& timeline = timelines_.timeline(entity);
      if (auto written = timeline_writer_->write(to_wire_timeline(topology_, agent_id(), entity, timeline));
          !written) {
        return unexpected(written.error());
      }
      published_versions_[entity] = timeline.version;
    }
  }

  expiry_thread_ = std::thread([this] { run_expiry(); });

  // Before any request is served: only what the journal restored is owed a heartbeat, not
  // what an agent reserves while this agent is still starting.
  if (options_.departed_after.count() > 0) owe_heartbeats();

  // Every handler takes the one mutex: requests are applied one at a time, whole.
  auto serve = [this]<class Req, class Rep>(Server<Req, Rep>& server, const char* service,
                                            void (TopologyAgent::*handler)(const Req&, dds::ReplyHandle<Rep>))
      -> Status {
    auto created = dds::ServiceServer<Req, Rep>::create(
        *participant_, kServiceArea, service,
        [this, handler](const Req& request, dds::ReplyHandle<Rep> reply) {
          (this->*handler)(request, std::move(reply));
        });
    if (!created) return unexpected(created.error());
    server = std::move(*created);
    return {};
  };
  for (auto status : {serve(prepare_server_, "reserve_prepare", &TopologyAgent::on_prepare),
                      serve(commit_server_, "reserve_commit", &TopologyAgent::on_commit),
                      serve(abort_server_, "reserve_abort", &TopologyAgent::on_abort),
                      serve(allocate_server_, "allocate", &TopologyAgent::on_allocate),
                      serve(release_server_, "release", &TopologyAgent::on_release),
                      serve(lock_server_, "lock", &TopologyAgent::on_lock),
                      serve(unlock_server_, "unlock", &TopologyAgent::on_unlock),
                      serve(delay_server_, "delay", &TopologyAgent::on_delay),
                      serve(cancel_server_, "cancel_route", &TopologyAgent::on_cancel_route),
                      serve(holdings_server_, "holdings", &TopologyAgent::on_holdings)}) {
    if (!status) return status;
  }

  if (auto watched = watch_logical_agents(); !watched) return watched;

  dds::HeartbeatOptions beat;
  beat.kind = "topology";
  beat.owns = served_partitions();
  auto heartbeat = dds::HeartbeatPublisher::create(*participant_, clock_, std::move(beat));
  if (!heartbeat) return unexpected(heartbeat.error());
  heartbeat_ = std::move(*heartbeat);
  return {};
}

TopologyAgent::~TopologyAgent() {
  // Departures first (the thread, then the directory it reads): a sweep publishes through
  // the writers and serves no request.
  {
    std::lock_guard lock(departed_mutex_);
    departed_stop_ = true;
  }
  departed_wake_.notify_all();
  if (departed_thread_.joinable()) departed_thread_.join();
  directory_.reset();
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  expiry_wake_.notify_all();
  if (expiry_thread_.joinable()) expiry_thread_.join();
  // Servers first, so that no handler runs any more; then the queued requests.
  prepare_server_.reset();
  commit_server_.reset();
  abort_server_.reset();
  allocate_server_.reset();
  release_server_.reset();
  lock_server_.reset();
  unlock_server_.reset();
  delay_server_.reset();
  cancel_server_.reset();
  holdings_server_.reset();
  std::lock_guard lock(mutex_);
  for (auto& [key, handle] : waiting_replies_) {
    send_error(handle, Error{ErrorCode::unavailable, "topology agent '" + agent_id() + "' shut down"});
  }
  waiting_replies_.clear();
  unanswered_commits_.clear();
}

Result<topology::EntityIndex> TopologyAgent::known_entity(const std::string& id) const {
  auto entity = topology_.find(id);
  if (!entity) {
    return fail(ErrorCode::not_found, "unknown entity '" + id + "' in topology '" + topology_.name() + "'");
  }
  return *entity;
}

Result<topology::EntityIndex> TopologyAgent::owned_entity(const std::string& id) const {
  auto entity = known_entity(id);
  if (!entity) return entity;
  if (!timelines_.owns(*entity)) {
    return fail(ErrorCode::not_found, "entity '" + id + "' belongs to partition '" +
                                          topology_.partition(*entity) + "', not served by topology agent '" +
                                          agent_id() + "'");
  }
  return *entity;
}

void TopologyAgent::on_prepare(const msg::ReservePrepareRequest& request,
                               dds::ReplyHandle<msg::ReservePrepareReply> reply) {
  std::lock_guard lock(mutex_);
  if (withdrawn_.contains({request.agent(), request.route()})) {
    // A routing agent retrying a route whose requester gave it up (it cancelled the route,
    // or crashed and its next life did): reserved now, nobody would ever cancel it.
    return send_error(reply, Error{ErrorCode::not_permitted, "route " + std::to_string(request.route()) + " of '" +
                                                                 request.agent() + "' was cancelled by its agent"});
  }
  if (const TimeNs now = clock_.now(); request.expires_at() > now && request.expires_at() - now > kLongestHold) {
    return send_error(reply, Error{ErrorCode::invalid_argument,
                                   "hold until " + std::to_string(request.expires_at()) + " ns: more than " +
                                       std::to_string(kLongestHold / kNsPerSecond) + " s after now on topology agent '" +
                                       agent_id() + "' (" + std::to_string(now) +
                                       " ns); do the agents share one clock (--epoch, --time-factor)?"});
  }
  std::vector<topology::Reservation> items;
  std::vector<topology::EntityIndex> touched;
  for (const auto& wire_item : request.items()) {
    auto item = from_wire(topology_, wire_item);
    if (!item) return send_error(reply, item.error());
    if (item->agent != request.agent() || item->route != request.route()) {
      return send_error(reply, Error{ErrorCode::invalid_argument,
                                     "item on '" + wire_item.entity() + "' is of agent '" + item->agent +
                                         "' route " + std::to_string(item->route) + ", the request of agent '" +
                                         request.agent() + "' route " + std::to_string(request.route())});
    }
    if (auto owned = owned_entity(wire_item.entity()); !owned) return send_error(reply, owned.error());
    touched.push_back(item->entity);
    items.push_back(std::move(*item));
  }
  std::vector<topology::ExpectedVersion> expected;
  for (const auto& wire_version : request.expected()) {
    auto entity = owned_entity(wire_version.entity());
    if (!entity) return send_error(reply, entity.error());
    expected.push_back(topology::ExpectedVersion{*entity, wire_version.version()});
  }
  auto prepared = timelines_.prepare(items, expected, request.expires_at());
  if (!prepared) return send_error(reply, prepared.error());
  PreparedRoute held{request.agent(), request.route(), {}};
  std::copy_if(items.begin(), items.end(), std::back_inserter(held.real_items),
               [](const topology::Reservation& item) { return !item.shadow(); });
  prepared_[*prepared] = std::move(held);
  if (auto saved = after_change({}); !saved) return send_error(reply, saved.error());
  msg::ReservePrepareReply out;
  out.prepare_id(*prepared);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (auto entity : touched) {
    msg::EntityVersion version;
    version.entity(topology_.id(entity));
    version.version(timelines_.version(entity));
    out.versions().push_back(std::move(version));
  }
  send_reply(reply, std::move(out));
}

void TopologyAgent::on_commit(const msg::ReserveCommitRequest& request, StatusHandle reply) {
  std::lock_guard lock(mutex_);
  auto committed = timelines_.commit(request.prepare_id());
  if (committed) {
    auto held = prepared_.extract(request.prepare_id());
    std::vector<msg::TopologyEvent> events;
    if (held) {
      // Windows as they are now (a delay may have moved held items before the commit).
      for (const auto& item : held.mapped().real_items) {
        auto now = find_real(timelines_.timeline(item.entity), item.agent, item.route, item.step);
        if (now) events.push_back(make_event(msg::EVENT_RESERVED, *now));
      }
    }
    committed = after_change(timelines_.take_grants(), std::move(events));
  }
  if (options_.drop_commit_replies) {
    spdlog::warn("drop-commit-replies: commit of prepare {} {}, reply not sent (test hook)", request.prepare_id(),
                 committed ? "applied" : "refused");
    unanswered_commits_.push_back(std::move(reply));
    return;
  }
  send_status(reply, committed);
}

void TopologyAgent::on_abort(const msg::ReserveAbortRequest& request, StatusHandle reply) {
  std::lock_guard lock(mutex_);
  auto aborted = timelines_.abort(request.prepare_id());
  if (aborted) {
    auto held = prepared_.extract(request.prepare_id());
    std::vector<msg::TopologyEvent> events;
    if (held) {
      events.emplace_back();
      events.back().kind(msg::EVENT_ABORTED);
      events.back().agent(held.mapped().agent);
      events.back().route(held.mapped().route);
    }
    aborted = after_change(timelines_.take_grants(), std::move(events));
  }
  send_status(reply, aborted);
}

bool TopologyAgent::first_step_of_route(topology::EntityIndex entity, const std::string& agent) const {
  const auto& reservations = timelines_.timeline(entity).reservations;
  const auto mine = std::find_if(reservations.begin(), reservations.end(), [&](const topology::Reservation& r) {
    return r.agent == agent && r.origin == entity && !r.prepared;
  });
  return mine != reservations.end() && mine->step == 0;
}

bool TopologyAgent::locked_now(topology::EntityIndex entity) const {
  const TimeNs now = clock_.now();
  const auto in_force = [&](topology::EntityIndex e) {
    if (!timelines_.owns(e)) return false;
    const auto& locks = timelines_.timeline(e).locks;
    return std::any_of(locks.begin(), locks.end(),
                       [&](const topology::Lock& lock) { return lock.window.start <= now && now < lock.window.end; });
  };
  if (in_force(entity)) return true;
  const auto conflicts = topology_.conflicts(entity);
  return std::any_of(conflicts.begin(), conflicts.end(), in_force);
}

void TopologyAgent::on_allocate(const msg::AllocateRequest& request, AllocateHandle reply) {
  std::lock_guard lock(mutex_);
  auto entity = owned_entity(request.entity());
  if (!entity) return send_error(reply, entity.error());
  const bool held_before = timelines_.timeline(*entity).holder == request.agent();
  // A lock in force now on the entity or its conflict set keeps vehicles from driving onto
  // it (I4), whatever the reservation order says: a vehicle running early on a route planned
  // around the lock must not be let on. Except the first step of a route: that is where the
  // vehicle stands, and it must be able to hold it again whenever it re-plans. Not queued:
  // the requester asks again (no grant comes when a lock ends).
  if (!held_before && !first_step_of_route(*entity, request.agent()) && locked_now(*entity)) {
    msg::AllocateReply out;
    out.granted(false);
    out.queue_position(0);
    return send_reply(reply, std::move(out));
  }
  auto allocation = timelines_.allocate(request.agent(), *entity);
  if (!allocation) return send_error(reply, allocation.error());
  // A grant made now is reported like a deferred one (NOTICE_ALLOCATION_GRANTED aside).
  std::vector<topology::Grant> granted_now;
  if (allocation->granted && !held_before) granted_now.push_back(topology::Grant{request.agent(), *entity});
  if (auto saved = after_change(granted_now, {}, false); !saved) return send_error(reply, saved.error());
  if (allocation->granted || !request.wait()) {
    msg::AllocateReply out;
    out.granted(allocation->granted);
    out.queue_position(static_cast<std::uint32_t>(allocation->queue_position));
    return send_reply(reply, std::move(out));
  }
  spdlog::debug("'{}' waits for '{}' at place {}", request.agent(), request.entity(),
                allocation->queue_position);
  const auto key = std::make_pair(request.agent(), *entity);
  if (auto earlier = waiting_replies_.find(key); earlier != waiting_replies_.end()) {
    // The agent asks again: its earlier call has timed out (it waits allocate_wait, then
    // asks anew). One reply waits per agent and entity, not one per try.
    msg::AllocateReply out;
    out.granted(false);
    out.queue_position(static_cast<std::uint32_t>(allocation->queue_position));
    send_reply(earlier->second, std::move(out));
    earlier->second = std::move(reply);
    return;
  }
  waiting_replies_.emplace(key, std::move(reply));
}

void TopologyAgent::on_release(const msg::ReleaseRequest& request, StatusHandle reply) {
  // An operator's release (droverctl release) checks this too, but with its own view of the
  // heartbeats: a logical agent this partition hears alive releases what it holds itself,
  // once its vehicle has left; released under it, another vehicle could drive in.
  if (reply.requester() != request.agent() && heard_alive(request.agent())) {
    return send_error(reply, Error{ErrorCode::conflict,
                                   "'" + request.agent() + "' is alive (topology agent '" + agent_id() +
                                       "' hears its heartbeat): it releases what it holds itself once its vehicle "
                                       "has left (stop its logical agent first if the vehicle is gone)"});
  }
  std::lock_guard lock(mutex_);
  if (request.shadows_only()) {
    const auto origin = known_entity(request.entity());
    if (!origin) return send_error(reply, origin.error());
    auto grants = timelines_.release_shadows(request.agent(), request.route(), request.step(), *origin);
    if (!grants) return send_error(reply, grants.error());
    return send_status(reply, after_change(*grants, {}));
  }
  auto entity = owned_entity(request.entity());
  if (!entity) return send_error(reply, entity.error());
  const auto step = timelines_.allocated_step(*entity);
  std::optional<topology::Reservation> held;
  if (step) held = find_real(timelines_.timeline(*entity), request.agent(), step->route, step->step);
  auto grants = timelines_.release(request.agent(), *entity);
  if (!grants) return send_error(reply, grants.error());
  std::vector<msg::TopologyEvent> events;
  if (held) events.push_back(make_event(msg::EVENT_RELEASED, *held));
  send_status(reply, after_change(*grants, std::move(events)));
}

void TopologyAgent::on_lock(const msg::LockRequest& request, dds::ReplyHandle<msg::LockReply> reply) {
  std::lock_guard lock(mutex_);
  auto entity = owned_entity(request.entity());
  if (!entity) return send_error(reply, entity.error());
  auto report = timelines_.lock(*entity, from_wire(request.window()), request.operator_id(), request.reason());
  if (!report) return send_error(reply, report.error());
  const std::string lock_id = wire_lock_id(agent_id(), report->id);
  spdlog::info("lock {} on '{}' by '{}': {} ({} reservations hit)", lock_id, request.entity(),
               request.operator_id(), request.reason(), report->hit.size());
  if (auto saved = after_change({}); !saved) return send_error(reply, saved.error());
  msg::TopologyEvent event;
  event.kind(msg::EVENT_LOCKED);
  event.agent(request.operator_id());
  event.entity(request.entity());
  event.window(request.window());
  event.lock_id(lock_id);
  event.reason(request.reason());
  record(std::move(event));
  msg::LockReply out;
  out.lock_id(lock_id);
  for (const auto& hit : report->hit) {
    out.hit().push_back(to_wire(topology_, hit));
    notify_hit(hit, lock_id);
  }
  send_reply(reply, std::move(out));
}

void TopologyAgent::on_unlock(const msg::UnlockRequest& request, StatusHandle reply) {
  std::lock_guard lock(mutex_);
  const std::string& id = request.lock_id();
  const std::string prefix = agent_id() + "/";
  topology::LockId number = 0;
  const char* digits = id.data() + std::min(prefix.size(), id.size());
  const auto parsed = std::from_chars(digits, id.data() + id.size(), number);
  if (id.rfind(prefix, 0) != 0 || parsed.ec != std::errc{} || parsed.ptr != id.data() + id.size() ||
      digits == id.data() + id.size()) {
    return send_error(reply, Error{ErrorCode::not_found, "lock '" + id + "' is not a lock of topology agent '" +
                                                             agent_id() + "' (its locks are '" + prefix +
                                                             "<number>')"});
  }
  std::optional<topology::Lock> removed;
  for (topology::EntityIndex entity = 0; entity < topology_.entity_count() && !removed; ++entity) {
    if (!timelines_.owns(entity)) continue;
    for (const auto& entry : timelines_.timeline(entity).locks) {
      if (entry.id == number) removed = entry;
    }
  }
  auto unlocked = timelines_.unlock(number);
  if (!unlocked) {
    return send_error(reply, Error{ErrorCode::not_found, "unknown lock '" + id + "'"});
  }
  spdlog::info("lock {} removed", id);
  auto saved = after_change({});
  if (saved && removed) {
    msg::TopologyEvent event;
    event.kind(msg::EVENT_UNLOCKED);
    event.agent(removed->operator_id);
    event.entity(topology_.id(removed->entity));
    event.window(to_wire(removed->window));
    event.lock_id(id);
    event.reason(removed->reason);
    record(std::move(event));
  }
  send_status(reply, saved);
}

void TopologyAgent::on_delay(const msg::DelayRequest& request, dds::ReplyHandle<msg::DelayReply> reply) {
  std::lock_guard lock(mutex_);
  auto entity = owned_entity(request.entity());
  if (!entity) return send_error(reply, entity.error());
  if (request.by() <= 0 || request.by() > kLongestDelay) {
    return send_error(reply, Error{ErrorCode::invalid_argument,
                                   "delay of " + std::to_string(request.by()) + " ns: must be positive and at most " +
                                       std::to_string(kLongestDelay) + " ns (a day)"});
  }
  auto report = timelines_.delay(request.agent(), request.route(), *entity, request.by());
  if (!report) return send_error(reply, report.error());
  if (auto saved = after_change({}); !saved) return send_error(reply, saved.error());
  msg::DelayReply out;
  for (const auto& shift : report->shifts) {
    msg::Shift wire_shift;
    wire_shift.agent(shift.agent);
    wire_shift.route(shift.route);
    wire_shift.from_step(shift.from_step);
    wire_shift.by(shift.by);
    out.shifts().push_back(wire_shift);
    // Each agent is told about its own route: where it first moved here, and the new window.
    msg::ReservationNotice notice;
    notice.agent(shift.agent);
    notice.kind(msg::NOTICE_SHIFTED);
    notice.route(shift.route);
    notice.shift(shift.by);
    notice.from_step(shift.from_step);
    msg::TopologyEvent event;
    event.kind(msg::EVENT_DELAYED);
    event.agent(shift.agent);
    event.route(shift.route);
    event.step(shift.from_step);
    event.shift(shift.by);
    if (auto moved = first_moved(shift.agent, shift.route, shift.from_step)) {
      notice.entity(topology_.id(moved->entity));
      notice.window(to_wire(moved->window));
      event.entity(notice.entity());
      event.window(notice.window());
    }
    notify(std::move(notice));
    record(std::move(event));
  }
  for (const auto& hit : report->hit_locks) {
    out.hit_locks().push_back(to_wire(topology_, hit));
    for (const auto& lock_entry : timelines_.timeline(hit.entity).locks) {
      if (lock_entry.window.overlaps(hit.window)) notify_hit(hit, wire_lock_id(agent_id(), lock_entry.id));
    }
  }
  send_reply(reply, std::move(out));
}

void TopologyAgent::on_cancel_route(const msg::CancelRouteRequest& request, StatusHandle reply) {
  std::lock_guard lock(mutex_);
  // Given up by its own agent (not undone by a routing agent, which re-plans it): never
  // reserved again, also when nothing of it is here yet (a prepare still on its way).
  if (reply.requester() == request.agent()) remember_withdrawn(request.agent(), request.route());
  auto grants = timelines_.cancel_route(request.agent(), request.route(), request.held_steps());
  if (!grants) return send_error(reply, grants.error());
  std::erase_if(prepared_, [&](const auto& entry) {
    return entry.second.agent == request.agent() && entry.second.route == request.route();
  });
  msg::TopologyEvent event;
  event.kind(msg::EVENT_CANCELLED);
  event.agent(request.agent());
  event.route(request.route());
  send_status(reply, after_change(*grants, {std::move(event)}));
}

void TopologyAgent::on_holdings(const msg::HoldingsRequest& request, dds::ReplyHandle<msg::HoldingsReply> reply) {
  if (request.agent().empty()) {
    return send_error(reply, Error{ErrorCode::invalid_argument, "holdings: empty agent id"});
  }
  msg::HoldingsReply out;
  {
    std::lock_guard lock(mutex_);
    const auto holdings = timelines_.holdings_of(request.agent());
    for (const auto& [entity, step] : holdings.held) {
      msg::HeldAllocation held;
      held.entity(topology_.id(entity));
      held.route(step.route);
      held.step(step.step);
      out.held().push_back(std::move(held));
    }
    out.routes(holdings.routes);
  }
  send_reply(reply, std::move(out));
}

void TopologyAgent::remember_withdrawn(const std::string& agent, topology::RouteId route) {
  if (!withdrawn_.insert({agent, route}).second) return;
  withdrawn_order_.emplace_back(agent, route);
  if (withdrawn_order_.size() > kWithdrawnKept) {
    withdrawn_.erase(withdrawn_order_.front());
    withdrawn_order_.pop_front();
  }
}

void TopologyAgent::run_expiry() {
  std::unique_lock lock(mutex_);
  while (!expiry_wake_.wait_for(lock, options_.expiry_period, [this] { return stopping_; })) {
    const auto expired = timelines_.expire(clock_.now());
    if (expired.empty()) continue;
    std::vector<msg::TopologyEvent> events;
    for (auto id : expired) {
      auto found = prepared_.find(id);
      if (found == prepared_.end()) continue;
      spdlog::info("prepared hold {} of '{}' route {} expired", id, found->second.agent, found->second.route);
      msg::ReservationNotice notice;
      notice.agent(found->second.agent);
      notice.kind(msg::NOTICE_PREPARE_EXPIRED);
      notice.route(found->second.route);
      notify(std::move(notice));
      events.emplace_back();
      events.back().kind(msg::EVENT_EXPIRED);
      events.back().agent(found->second.agent);
      events.back().route(found->second.route);
      prepared_.erase(found);
    }
    if (!after_change(timelines_.take_grants(), std::move(events))) return;
  }
}

Status TopologyAgent::after_change(const std::vector<topology::Grant>& grants,
                                  std::vector<msg::TopologyEvent> events, bool notify_grants) {
  std::vector<topology::EntityIndex> changed;
  for (topology::EntityIndex entity = 0; entity < topology_.entity_count(); ++entity) {
    if (timelines_.owns(entity) && timelines_.timeline(entity).version != published_versions_[entity]) {
      changed.push_back(entity);
    }
  }
  if (journal_failed_) {
    // What changed in memory since the failed save is neither stored nor published: the
    // restart continues from the journal, where none of it is (a later save would store the
    // change whose request was refused).
    return fail(ErrorCode::unavailable, "topology agent '" + participant_->agent_id() +
                                            "' is stopping: its journal could not be saved");
  }
  if (journal_ && !changed.empty()) {
    if (auto saved = journal_->save(timelines_.snapshot(changed)); !saved) {
      spdlog::critical("journal not saved, stopping (a restart continues from the journal): {}",
                       saved.error().message);
      journal_failed_ = true;
      dds::request_shutdown();
      return saved;
    }
  }
  // Entities nobody holds first: a release that grants a conflicting entity to a waiting
  // agent changes both in one step, and an observer reading the states in publication order
  // must never see the new holder while the old one still shows as holding.
  std::stable_partition(changed.begin(), changed.end(), [&](topology::EntityIndex entity) {
    return !timelines_.timeline(entity).holder.has_value();
  });
  for (auto entity : changed) {
    const auto& timeline = timelines_.timeline(entity);
    if (auto written = timeline_writer_->write(to_wire_timeline(topology_, agent_id(), entity, timeline));
        !written) {
      spdlog::error("timeline of '{}' not published: {}", topology_.id(entity), written.error().message);
      continue;
    }
    published_versions_[entity] = timeline.version;
  }
  for (auto& event : events) record(std::move(event));
  for (const auto& grant : grants) {
    const auto step = timelines_.allocated_step(grant.entity);
    std::optional<topology::Reservation> held;
    if (step) held = find_real(timelines_.timeline(grant.entity), grant.agent, step->route, step->step);
    if (held) record(make_event(msg::EVENT_ALLOCATED, *held));
    if (!notify_grants) continue;
    msg::ReservationNotice notice;
    notice.agent(grant.agent);
    notice.kind(msg::NOTICE_ALLOCATION_GRANTED);
    notice.entity(topology_.id(grant.entity));
    if (held) {
      notice.route(held->route);
      notice.from_step(held->step);
      notice.window(to_wire(held->window));
    }
    notify(std::move(notice));
  }
  // Queued requests: answered once their agent holds the entity, or with an error once it
  // no longer waits (its reservations there were cancelled).
  for (auto it = waiting_replies_.begin(); it != waiting_replies_.end();) {
    const auto& [agent, entity] = it->first;
    const auto& timeline = timelines_.timeline(entity);
    if (timeline.holder == agent) {
      msg::AllocateReply out;
      out.granted(true);
      send_reply(it->second, std::move(out));
    } else if (std::find(timeline.waiting.begin(), timeline.waiting.end(), agent) == timeline.waiting.end()) {
      send_error(it->second, Error{ErrorCode::not_found, "allocation request of '" + agent + "' on '" +
                                                             topology_.id(entity) +
                                                             "' withdrawn: its reservations there are gone"});
    } else {
      ++it;
      continue;
    }
    it = waiting_replies_.erase(it);
  }
  return {};
}

void TopologyAgent::notify(msg::ReservationNotice notice) {
  notice.source(agent_id());
  if (auto written = notice_writer_->write(notice); !written) {
    spdlog::error("notice to '{}' not sent: {}", notice.agent(), written.error().message);
  }
}

void TopologyAgent::notify_hit(const topology::Reservation& hit, const std::string& lock_id) {
  msg::ReservationNotice notice;
  notice.agent(hit.agent);
  notice.kind(msg::NOTICE_LOCK_HIT);
  notice.route(hit.route);
  notice.entity(topology_.id(hit.entity));
  notice.from_step(hit.step);
  notice.lock_id(lock_id);
  notice.window(to_wire(hit.window));
  notify(std::move(notice));
}

void TopologyAgent::record(msg::TopologyEvent event) {
  event.time(clock_.now());
  event.source(agent_id());
  event.serial(++event_serial_);
  if (auto written = event_writer_->write(event); !written) {
    spdlog::error("event {} not published: {}", event.serial(), written.error().message);
  }
}

msg::TopologyEvent TopologyAgent::make_event(msg::TopologyEventKind kind, const topology::Reservation& item) const {
  msg::TopologyEvent event;
  event.kind(kind);
  event.agent(item.agent);
  event.route(item.route);
  event.step(item.step);
  event.entity(topology_.id(item.entity));
  event.window(to_wire(item.window));
  return event;
}

std::optional<topology::Reservation> TopologyAgent::first_moved(const topology::AgentId& agent,
                                                                topology::RouteId route,
                                                                std::uint32_t from_step) const {
  std::optional<topology::Reservation> best;
  auto better = [&](const topology::Reservation& item) {
    if (!best) return true;
    if (item.step != best->step) return item.step < best->step;
    return best->shadow() && !item.shadow();
  };
  for (topology::EntityIndex entity = 0; entity < topology_.entity_count(); ++entity) {
    if (!timelines_.owns(entity)) continue;
    for (const auto& item : timelines_.timeline(entity).reservations) {
      if (item.agent == agent && item.route == route && item.step >= from_step && better(item)) best = item;
    }
  }
  return best;
}

}  // namespace drover::topology_agent

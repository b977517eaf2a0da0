#include "drover/dds/detail/client_core.hpp"

#include "drover/dds/detail/requester_filter.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include <fastdds/rtps/common/WriteParams.h>

namespace drover::dds::detail {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::SampleIdentity;

namespace {

std::string ms_text(std::chrono::milliseconds timeout) {
  return std::to_string(timeout.count()) + " ms";
}

}  // namespace

ClientCore::ClientCore(Participant& participant, ServiceTopics topics)
    : participant_(participant), topics_(std::move(topics)) {}

Result<std::unique_ptr<ClientCore>> ClientCore::create(Participant& participant, ServiceTopics topics,
                                                       fdds::TypeSupport request_type,
                                                       fdds::TypeSupport reply_type) {
  std::unique_ptr<ClientCore> self(new ClientCore(participant, std::move(topics)));
  ClientCore* core = self.get();

  // Replies reach only their requester: the filter keeps samples whose header names this
  // agent (evaluated by the server's writer for each client's reader).
  ReaderSpec reply_spec{core->topics_.reply,         std::move(reply_type),
                        TopicQos::service(),         kRequesterFilterExpression,
                        {participant.agent_id()},    kRequesterFilterClass,
                        Dispatch::listener_thread};
  auto reader = ReaderCore::create(
      participant, std::move(reply_spec),
      [core](std::shared_ptr<void>& reply, const fdds::SampleInfo& info) { core->on_reply(reply, info); },
      {}, [core] { core->on_match_change(); });
  if (!reader) return unexpected(reader.error());
  {
    std::lock_guard lock(core->state_mutex_);
    core->reply_reader_id_ = (*reader)->guid().entityId.to_uint32();
    core->reply_reader_ = std::move(*reader);
  }

  auto writer = WriterCore::create(participant, core->topics_.request, std::move(request_type),
                                   TopicQos::service(), [core] { core->on_match_change(); });
  if (!writer) return unexpected(writer.error());
  {
    std::lock_guard lock(core->state_mutex_);
    core->writer_guid_ = (*writer)->guid();
    core->request_writer_ = std::move(*writer);
  }
  return self;
}

ClientCore::~ClientCore() {
  std::unique_ptr<WriterCore> writer;
  std::unique_ptr<ReaderCore> reader;
  {
    // Endpoint callbacks during their deletion then find no endpoints and do nothing.
    std::lock_guard lock(state_mutex_);
    writer = std::move(request_writer_);
    reader = std::move(reply_reader_);
  }
  writer.reset();
  reader.reset();
}

std::optional<ServerRef> ClientCore::pick_server(const std::string& responder) {
  if (!request_writer_ || !reply_reader_) return std::nullopt;
  const std::vector<GuidPrefix_t> readers = request_writer_->matched_participants();
  std::vector<ServerRef> candidates;
  for (const GuidPrefix_t& prefix : readers) {
    if (!reply_reader_->matched(prefix)) continue;
    auto name = participant_.participant_name(prefix);
    if (!name) continue;
    if (!responder.empty() && *name != responder) continue;
    candidates.push_back(ServerRef{prefix, std::move(*name)});
  }
  if (candidates.empty()) return std::nullopt;
  std::sort(candidates.begin(), candidates.end(),
            [](const ServerRef& a, const ServerRef& b) { return a.name < b.name; });
  return candidates[next_server_++ % candidates.size()];
}

Result<ServerRef> ClientCore::wait_for_server(const std::string& responder, Deadline deadline,
                                              std::chrono::milliseconds timeout) {
  std::unique_lock lock(state_mutex_);
  std::optional<ServerRef> server;
  state_changed_.wait_until(lock, deadline, [&] { return (server = pick_server(responder)).has_value(); });
  if (server) return std::move(*server);
  const std::string who = responder.empty() ? "no server" : "no server '" + responder + "'";
  return fail(ErrorCode::timeout, who + " for service '" + topics_.name + "' matched within " +
                                      ms_text(timeout) + " (is it running on domain " +
                                      std::to_string(participant_.domain_id()) + "?)");
}

Result<std::shared_ptr<void>> ClientCore::send(void* request, const ServerRef& server,
                                               Deadline deadline, std::chrono::milliseconds timeout) {
  Call call{server, nullptr, std::nullopt};
  SampleIdentity identity;
  {
    // Writes are serialised with their registration, so at most one request at a time is
    // written but not yet registered: a reply for an unregistered sequence number above
    // the last registered one overtook its call (kept); below it, its call gave up (late).
    std::lock_guard write_lock(write_mutex_);
    eprosima::fastrtps::rtps::WriteParams params;
    if (auto written = request_writer_->write(request, params); !written) {
      return unexpected(written.error());
    }
    identity = params.sample_identity();
    std::lock_guard lock(state_mutex_);
    ++stats_.requests_sent;
    last_registered_ = identity.sequence_number();
    if (auto early = early_replies_.find(identity.sequence_number()); early != early_replies_.end()) {
      call.reply = std::move(early->second);
    }
    early_replies_.erase(early_replies_.begin(), early_replies_.upper_bound(identity.sequence_number()));
    if (!call.reply) pending_.emplace(identity, &call);
  }
  if (!call.reply) {
    std::unique_lock lock(state_mutex_);
    state_changed_.wait_until(lock, deadline, [&] { return call.reply != nullptr || call.error.has_value(); });
    pending_.erase(identity);
  }
  if (call.reply) return std::move(call.reply);
  if (call.error) return unexpected(std::move(*call.error));
  return fail(ErrorCode::timeout, "server '" + server.name + "' did not reply to '" + topics_.name +
                                      "' within " + ms_text(timeout));
}

void ClientCore::on_reply(std::shared_ptr<void>& reply, const fdds::SampleInfo& info) {
  const SampleIdentity& related = info.related_sample_identity;
  {
    std::lock_guard lock(state_mutex_);
    ++stats_.replies_received;
    if (related.writer_guid() != writer_guid_) {
      ++stats_.replies_for_other_clients;
      return;
    }
    if (auto it = pending_.find(related); it != pending_.end()) {
      it->second->reply = std::move(reply);
    } else if (related.sequence_number() > last_registered_) {
      early_replies_[related.sequence_number()] = std::move(reply);
      return;
    } else {
      ++stats_.late_replies;
      return;
    }
  }
  state_changed_.notify_all();
}

void ClientCore::on_match_change() {
  {
    std::lock_guard lock(state_mutex_);
    if (request_writer_ && reply_reader_) {
      // A call whose server is no longer matched on both topics can never get its reply.
      for (auto& [identity, call] : pending_) {
        if (call->error || call->reply) continue;
        if (!request_writer_->matched(call->server.participant) ||
            !reply_reader_->matched(call->server.participant)) {
          call->error = Error{ErrorCode::unavailable, "server '" + call->server.name + "' of '" +
                                                          topics_.name + "' went away before replying"};
        }
      }
    }
  }
  state_changed_.notify_all();
}

ClientStats ClientCore::stats() const {
  std::lock_guard lock(state_mutex_);
  return stats_;
}

}  // namespace drover::dds::detail

// `drover bench rpc`: the cost of the DDS service layer over raw Fast DDS.
//
// The benchmark starts `drover bench rpc-server` as a second process. That process serves
// drover/diagnostics/ping with ServiceServer (echo) and, beside it, a raw ping-pong: a
// plain DataReader on drover/bench/raw/ping whose listener writes each sample straight back
// on drover/bench/raw/pong. The client alternates one raw round trip and one service call
// with the same payload, so that both see the same machine load, and prints one JSON line.
//
// With --route, the service measured is the routing agent's route service instead of the
// ping echo: the benchmark also starts `drover topology-agent` (the whole --topology) and
// `drover routing-agent` as processes and times test-route requests FROM -> TO, against
// raw ping-pongs whose payload is the serialized size of the route reply.

#include "bench/bench_rpc.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fmt/format.h>

#include "diagnostics.h"
#include "routing.h"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/shutdown_signal.hpp"
#include "drover/topology/topology_file.hpp"

extern char** environ;

namespace drover::bench {
namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using PingClient = dds::ServiceClient<msg::PingRequest, msg::PingReply>;
using PingServer = dds::ServiceServer<msg::PingRequest, msg::PingReply>;
using RouteClient = dds::ServiceClient<msg::RouteRequest, msg::RouteReply>;

constexpr const char* kRawPingTopic = "drover/bench/raw/ping";
constexpr const char* kRawPongTopic = "drover/bench/raw/pong";
constexpr const char* kServerId = "bench-rpc-server";
constexpr auto kStartTimeout = 20s;
constexpr auto kCallTimeout = 5s;

struct RpcArguments {
  std::uint32_t domain_id = 99;
  int calls = 2000;
  int warmup = 200;
  std::size_t payload_bytes = 512;
  /// Route mode: the topology file and the test route measured.
  bool route = false;
  std::string topology_file = "launch/topologies/warehouse.json";
  std::string route_from = "aisle-00-y08";
  std::string route_to = "aisle-02-y20";
};

/// A raw DataReader with its listener; deleted before the participant.
class RawReader {
 public:
  RawReader() = default;
  RawReader(const RawReader&) = delete;
  RawReader& operator=(const RawReader&) = delete;
  ~RawReader() {
    if (reader_ != nullptr) participant_->subscriber().delete_datareader(reader_);
  }

  Status open(dds::Participant& participant, const std::string& topic_name,
              fdds::DataReaderListener* listener) {
    auto topic = participant.topic<msg::PingRequest>(topic_name);
    if (!topic) return unexpected(topic.error());
    participant_ = &participant;
    reader_ = participant.subscriber().create_datareader(
        *topic, dds::reader_qos(dds::TopicQos::service()), listener, fdds::StatusMask::data_available());
    // The participant's subscriber creates readers disabled.
    if (reader_ == nullptr || reader_->enable() != ReturnCode_t::RETCODE_OK) {
      return fail(ErrorCode::unavailable, "cannot create the raw reader on " + topic_name);
    }
    return {};
  }
  fdds::DataReader& get() { return *reader_; }

 private:
  dds::Participant* participant_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
};

class RawWriter {
 public:
  RawWriter() = default;
  RawWriter(const RawWriter&) = delete;
  RawWriter& operator=(const RawWriter&) = delete;
  ~RawWriter() {
    if (writer_ != nullptr) participant_->publisher().delete_datawriter(writer_);
  }

  Status open(dds::Participant& participant, const std::string& topic_name) {
    auto topic = participant.topic<msg::PingRequest>(topic_name);
    if (!topic) return unexpected(topic.error());
    participant_ = &participant;
    writer_ = participant.publisher().create_datawriter(*topic, dds::writer_qos(dds::TopicQos::service()));
    if (writer_ == nullptr) return fail(ErrorCode::unavailable, "cannot create the raw writer on " + topic_name);
    return {};
  }
  fdds::DataWriter& get() { return *writer_; }

 private:
  dds::Participant* participant_ = nullptr;
  fdds::DataWriter* writer_ = nullptr;
};

/// Server side of the raw ping-pong: answers inside Fast DDS's listener, as a minimal
/// hand-written responder would.
class RawEcho final : public fdds::DataReaderListener {
 public:
  explicit RawEcho(RawWriter& pong) : pong_(pong) {}
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) pong_.get().write(&sample_);
    }
  }

 private:
  RawWriter& pong_;
  msg::PingRequest sample_;
};

/// Client side of the raw ping-pong: hands each pong's text to the waiting caller.
class RawPongInbox final : public fdds::DataReaderListener {
 public:
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    msg::PingRequest sample;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      {
        std::lock_guard lock(mutex_);
        last_text_ = sample.text();
      }
      arrived_.notify_all();
    }
  }
  /// Waits for the pong whose text is `text`. \return whether it came in time.
  bool wait_for(const std::string& text, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return arrived_.wait_for(lock, timeout, [&] { return last_text_ == text; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::string last_text_;
};

std::unique_ptr<dds::Participant> open_participant(std::uint32_t domain, const std::string& id) {
  dds::ParticipantOptions options;
  options.domain_id = domain;
  options.agent_id = id;
  auto participant = dds::Participant::create(options);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return nullptr;
  }
  return std::move(*participant);
}

/// `drover bench rpc-server`: the other process. Runs until SIGTERM / SIGINT or until its
/// parent (the benchmark) dies.
int run_server(const RpcArguments& arguments) {
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (auto installed = dds::install_shutdown_handlers(); !installed) {
    std::cerr << "error: " << installed.error().message << "\n";
    return cli::kExitFailure;
  }
  if (getppid() == 1) return cli::kExitOk;  // the benchmark is already gone
  auto participant = open_participant(arguments.domain_id, kServerId);
  if (!participant) return cli::kExitFailure;

  RawWriter pong;
  RawEcho echo(pong);
  RawReader ping;
  auto server = PingServer::create(*participant, "diagnostics", "ping",
                                   [](const msg::PingRequest& request, dds::ReplyHandle<msg::PingReply> reply) {
                                     msg::PingReply answer;
                                     answer.text(request.text());
                                     answer.payload(request.payload());
                                     (void)reply.send(std::move(answer));
                                   });
  Status opened = pong.open(*participant, kRawPongTopic);
  if (opened) opened = ping.open(*participant, kRawPingTopic, &echo);
  if (!server || !opened) {
    std::cerr << "error: " << (server ? opened.error().message : server.error().message) << "\n";
    return cli::kExitFailure;
  }
  dds::wait_for_shutdown();
  return cli::kExitOk;
}

/// A child process running `drover ARGS...` (the rpc-server, or an agent); SIGTERM and
/// reaped on destruction.
class ServerProcess {
 public:
  static std::optional<ServerProcess> start(std::vector<std::string> args) {
    args.insert(args.begin(), "drover");
    std::vector<char*> argv;
    for (auto& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0) return std::nullopt;
    return ServerProcess(pid);
  }
  ServerProcess(ServerProcess&& other) noexcept : pid_(std::exchange(other.pid_, -1)) {}
  ServerProcess& operator=(ServerProcess&&) = delete;
  ~ServerProcess() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    ::waitpid(pid_, nullptr, 0);
  }

 private:
  explicit ServerProcess(pid_t pid) : pid_(pid) {}
  pid_t pid_;
};

double percentile_us(std::vector<double> samples_us, double fraction) {
  std::sort(samples_us.begin(), samples_us.end());
  const auto rank = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(samples_us.size())));
  return samples_us[std::clamp<std::size_t>(rank, 1, samples_us.size()) - 1];
}

double micros_since(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

/// In route mode: the topology agent and the routing agent processes, the route client,
/// and the test route it asks for.
struct RouteTarget {
  std::vector<ServerProcess> agents;
  std::unique_ptr<RouteClient> client;
  msg::RouteRequest request;
  std::size_t request_bytes = 0;
  std::size_t reply_bytes = 0;
  std::size_t steps = 0;
};

/// Starts the agents and asks for the test route until it comes back (the routing agent
/// learns the topology first). \return the target, or the exit code.
std::variant<RouteTarget, int> start_route_target(const RpcArguments& arguments, dds::Participant& participant) {
  RouteTarget target;
  const std::string domain = std::to_string(arguments.domain_id);
  for (std::vector<std::string> args :
       {std::vector<std::string>{"topology-agent", "--topology", arguments.topology_file, "--domain", domain,
                                 "--id", "bench-topology", "--log-level", "warn"},
        std::vector<std::string>{"routing-agent", "--domain", domain, "--id", "bench-routing", "--log-level",
                                 "warn"}}) {
    auto process = ServerProcess::start(args);
    if (!process) {
      std::cerr << "error: cannot start drover " << args.front() << "\n";
      return cli::kExitFailure;
    }
    target.agents.push_back(std::move(*process));
  }
  auto client = RouteClient::create(participant, "routing", "route");
  if (!client) {
    std::cerr << "error: " << client.error().message << "\n";
    return cli::kExitFailure;
  }
  target.client = std::move(*client);
  msg::RouteRequest& request = target.request;
  request.agent("bench-vehicle");
  request.real(false);
  request.vehicle().id("bench-vehicle");
  request.vehicle().max_speed(1.0);
  request.vehicle().acceleration(1.0);
  request.vehicle().deceleration(1.0);
  request.vehicle().length(1.0);
  request.vehicle().width(1.0);
  request.start(arguments.route_from);
  msg::RouteStop stop;
  stop.vertex(arguments.route_to);
  request.stops().push_back(stop);
  auto reply = target.client->call(request, kStartTimeout);
  if (!reply) {
    std::cerr << "error: the routing agent did not answer: " << reply.error().message << "\n";
    return cli::kExitNoAnswer;
  }
  if (reply->error().code() != msg::ERROR_NONE) {
    std::cerr << "error: test route " << arguments.route_from << " -> " << arguments.route_to << ": "
              << reply->error().message() << "\n";
    return cli::kExitBadInput;
  }
  target.request_bytes = msg::RouteRequest::getCdrSerializedSize(request);
  target.reply_bytes = msg::RouteReply::getCdrSerializedSize(*reply);
  target.steps = reply->steps().size();
  return target;
}

/// Route mode's input, checked before any process starts: the topology loads and holds both
/// ends of the test route. \return kExitOk, or kExitBadInput with the problems printed.
int check_route_input(const RpcArguments& arguments) {
  const auto loaded = topology::load_topology_file(arguments.topology_file);
  if (!loaded) {
    return cli::report_bad_file(arguments.topology_file, loaded.error());
  }
  for (const std::string& end : {arguments.route_from, arguments.route_to}) {
    const auto found = loaded->find(end);
    if (!found || !loaded->is_vertex(*found)) {
      std::cerr << "error: " << arguments.topology_file << ": no vertex '" << end
                << "' (--from and --to name vertices of the topology)\n";
      return cli::kExitBadInput;
    }
  }
  return cli::kExitOk;
}

/// The measured run; \return the exit code.
int run_benchmark(const RpcArguments& arguments) {
  if (arguments.route) {
    if (const int checked = check_route_input(arguments); checked != cli::kExitOk) return checked;
  }
  auto server_process = ServerProcess::start({"bench", "rpc-server", "--domain", std::to_string(arguments.domain_id)});
  if (!server_process) {
    std::cerr << "error: cannot start the rpc-server process\n";
    return cli::kExitFailure;
  }
  auto participant = open_participant(arguments.domain_id, "bench-rpc-client");
  if (!participant) return cli::kExitFailure;

  auto client = PingClient::create(*participant, "diagnostics", "ping");
  RawWriter ping;
  RawPongInbox inbox;
  RawReader pong;
  Status opened = ping.open(*participant, kRawPingTopic);
  if (opened) opened = pong.open(*participant, kRawPongTopic, &inbox);
  if (!client || !opened) {
    std::cerr << "error: " << (client ? opened.error().message : client.error().message) << "\n";
    return cli::kExitFailure;
  }
  if (auto server = (*client)->wait_for_server(kStartTimeout); !server) {
    std::cerr << "error: " << server.error().message << "\n";
    return cli::kExitNoAnswer;
  }

  std::optional<RouteTarget> route;
  std::size_t payload_bytes = arguments.payload_bytes;
  if (arguments.route) {
    auto started = start_route_target(arguments, *participant);
    if (auto* code = std::get_if<int>(&started)) return *code;
    route.emplace(std::move(std::get<RouteTarget>(started)));
    // The raw ping carries what the route reply carries (the larger of the two messages).
    payload_bytes = route->reply_bytes;
  }

  msg::PingRequest request;
  request.payload(std::vector<std::uint8_t>(payload_bytes, 0x5a));
  const std::vector<std::uint8_t> payload = request.payload();

  // Raw readiness: a raw ping written before the server's reader has matched ours is lost
  // (VOLATILE), so pings are repeated until one comes back.
  bool raw_ready = false;
  for (int attempt = 0; attempt < 40 && !raw_ready; ++attempt) {
    request.text("ready-" + std::to_string(attempt));
    ping.get().write(&request);
    raw_ready = inbox.wait_for(request.text(), 500ms);
  }
  if (!raw_ready) {
    std::cerr << "error: the raw ping-pong partner did not answer\n";
    return cli::kExitNoAnswer;
  }

  std::vector<double> raw_us;
  std::vector<double> service_us;
  raw_us.reserve(static_cast<std::size_t>(arguments.calls));
  service_us.reserve(static_cast<std::size_t>(arguments.calls));
  for (int i = -arguments.warmup; i < arguments.calls; ++i) {
    request.text("raw-" + std::to_string(i));
    const auto raw_start = Clock::now();
    if (!ping.get().write(&request) || !inbox.wait_for(request.text(), kCallTimeout)) {
      std::cerr << "error: raw round trip " << i << " failed\n";
      return cli::kExitFailure;
    }
    const double raw = micros_since(raw_start);

    double service = 0;
    if (route) {
      const auto service_start = Clock::now();
      auto reply = route->client->call(route->request, kCallTimeout);
      service = micros_since(service_start);
      if (!reply || reply->error().code() != msg::ERROR_NONE || reply->steps().size() != route->steps) {
        std::cerr << "error: route request " << i << ": "
                  << (reply ? reply->error().message() : reply.error().message) << "\n";
        return cli::kExitFailure;
      }
    } else {
      request.text("service-" + std::to_string(i));
      const auto service_start = Clock::now();
      auto reply = (*client)->call(request, kCallTimeout);
      service = micros_since(service_start);
      if (!reply || reply->payload() != payload) {
        std::cerr << "error: service call " << i << ": "
                  << (reply ? "payload not echoed" : reply.error().message) << "\n";
        return cli::kExitFailure;
      }
    }
    if (i >= 0) {
      raw_us.push_back(raw);
      service_us.push_back(service);
    }
  }

  const double raw_p50 = percentile_us(raw_us, 0.50);
  const double raw_p99 = percentile_us(raw_us, 0.99);
  const double service_p50 = percentile_us(service_us, 0.50);
  const double service_p99 = percentile_us(service_us, 0.99);
  if (route) {
    std::cout << fmt::format(
                     "{{\"benchmark\": \"rpc-route\", \"route\": \"{} -> {}\", \"route_steps\": {}, "
                     "\"request_bytes\": {}, \"reply_bytes\": {}, \"payload_bytes\": {}, \"calls\": {}, "
                     "\"raw_p50_us\": {:.1f}, \"raw_p99_us\": {:.1f}, \"route_p50_us\": {:.1f}, "
                     "\"route_p99_us\": {:.1f}, \"ratio_p50\": {:.3f}, \"ratio_p99\": {:.3f}}}",
                     arguments.route_from, arguments.route_to, route->steps, route->request_bytes,
                     route->reply_bytes, payload_bytes, arguments.calls, raw_p50, raw_p99, service_p50, service_p99,
                     service_p50 / raw_p50, service_p99 / raw_p99)
              << std::endl;
    return cli::kExitOk;
  }
  std::cout << fmt::format(
                   "{{\"benchmark\": \"rpc\", \"payload_bytes\": {}, \"calls\": {}, \"raw_p50_us\": {:.1f}, "
                   "\"raw_p99_us\": {:.1f}, \"service_p50_us\": {:.1f}, \"service_p99_us\": {:.1f}, "
                   "\"ratio_p50\": {:.3f}, \"ratio_p99\": {:.3f}}}",
                   arguments.payload_bytes, arguments.calls, raw_p50, raw_p99, service_p50, service_p99,
                   service_p50 / raw_p50, service_p99 / raw_p99)
            << std::endl;
  return cli::kExitOk;
}

}  // namespace

void add_bench_rpc_command(CLI::App& bench, cli::CommandContext& context) {
  auto arguments = std::make_shared<RpcArguments>();
  auto* rpc = bench.add_subcommand(
      "rpc", "Request/reply round trips over the DDS service layer vs a raw DDS ping-pong");
  rpc->add_option("--domain", arguments->domain_id, "DDS domain id (default 99)")->transform(cli::whole_in(0, 232));
  rpc->add_option("--calls", arguments->calls, "Measured round trips of each kind (default 2000)")
      ->transform(cli::whole_in(1, 10'000'000));
  rpc->add_option("--warmup", arguments->warmup, "Unmeasured round trips first (default 200)")
      ->transform(cli::whole_in(0, 1'000'000));
  rpc->add_option("--payload", arguments->payload_bytes, "Payload bytes per request (default 512)")
      ->transform(cli::whole_in(0, 1'000'000));
  rpc->add_flag("--route", arguments->route,
                "Measure the routing agent's route service (test routes) instead of the ping echo; starts a "
                "topology agent and a routing agent");
  rpc->add_option("--topology", arguments->topology_file,
                  "Route mode: topology the agents serve (default launch/topologies/warehouse.json)")
      ->check(CLI::ExistingFile);
  rpc->add_option("--from", arguments->route_from, "Route mode: start vertex (default aisle-00-y08)");
  rpc->add_option("--to", arguments->route_to, "Route mode: destination vertex (default aisle-02-y20)");
  rpc->callback([arguments, &context] { context.exit_code = run_benchmark(*arguments); });

  // The partner process; started by `rpc` itself, so hidden from the help.
  auto* server = bench.add_subcommand("rpc-server", "Partner process of `drover bench rpc`");
  server->group("");
  server->add_option("--domain", arguments->domain_id, "DDS domain id")->transform(cli::whole_in(0, 232));
  server->callback([arguments, &context] { context.exit_code = run_server(*arguments); });
}

}  // namespace drover::bench

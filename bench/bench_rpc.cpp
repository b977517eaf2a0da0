// `drover bench rpc`: the cost of the DDS service layer over raw Fast DDS.
//
// The benchmark starts `drover bench rpc-server` as a second process. That process serves
// drover/diagnostics/ping with ServiceServer (echo) and, beside it, a raw ping-pong: a
// plain DataReader on drover/bench/raw/ping whose listener writes each sample straight back
// on drover/bench/raw/pong. The client alternates one raw round trip and one service call
// with the same payload, so that both see the same machine load, and prints one JSON line.

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
#include <vector>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fmt/format.h>

#include "diagnostics.h"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"
#include "drover/dds/service_client.hpp"
#include "drover/dds/service_server.hpp"
#include "drover/dds/shutdown_signal.hpp"

extern char** environ;

namespace drover::bench {
namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using PingClient = dds::ServiceClient<msg::PingRequest, msg::PingReply>;
using PingServer = dds::ServiceServer<msg::PingRequest, msg::PingReply>;

constexpr const char* kRawPingTopic = "drover/bench/raw/ping";
constexpr const char* kRawPongTopic = "drover/bench/raw/pong";
constexpr const char* kServerId = "bench-rpc-server";
constexpr auto kStartTimeout = 20s;
constexpr auto kCallTimeout = 5s;

struct RpcArguments {
  std::uint32_t domain_id = 231;
  int calls = 2000;
  int warmup = 200;
  std::size_t payload_bytes = 512;
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

/// The child process running `drover bench rpc-server`; SIGTERM and reaped on destruction.
class ServerProcess {
 public:
  static std::optional<ServerProcess> start(std::uint32_t domain) {
    std::vector<std::string> args{"drover", "bench", "rpc-server", "--domain", std::to_string(domain)};
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

/// The measured run; \return the exit code.
int run_benchmark(const RpcArguments& arguments) {
  auto server_process = ServerProcess::start(arguments.domain_id);
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

  msg::PingRequest request;
  request.payload(std::vector<std::uint8_t>(arguments.payload_bytes, 0x5a));
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

    request.text("service-" + std::to_string(i));
    const auto service_start = Clock::now();
    auto reply = (*client)->call(request, kCallTimeout);
    const double service = micros_since(service_start);
    if (!reply || reply->payload() != payload) {
      std::cerr << "error: service call " << i << ": "
                << (reply ? "payload not echoed" : reply.error().message) << "\n";
      return cli::kExitFailure;
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
  rpc->add_option("--domain", arguments->domain_id, "DDS domain id (default 231)")->check(CLI::Range(0, 232));
  rpc->add_option("--calls", arguments->calls, "Measured round trips of each kind (default 2000)")
      ->check(CLI::Range(1, 10'000'000));
  rpc->add_option("--warmup", arguments->warmup, "Unmeasured round trips first (default 200)")
      ->check(CLI::Range(0, 1'000'000));
  rpc->add_option("--payload", arguments->payload_bytes, "Payload bytes per request (default 512)")
      ->check(CLI::Range(0, 1'000'000));
  rpc->callback([arguments, &context] { context.exit_code = run_benchmark(*arguments); });

  // The partner process; started by `rpc` itself, so hidden from the help.
  auto* server = bench.add_subcommand("rpc-server", "Partner process of `drover bench rpc`");
  server->group("");
  server->add_option("--domain", arguments->domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  server->callback([arguments, &context] { context.exit_code = run_server(*arguments); });
}

}  // namespace drover::bench

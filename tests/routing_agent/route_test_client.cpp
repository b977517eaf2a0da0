// route_test_client: a client process of the route service for the routing agent's tests.
// Sends --count real-route requests from --threads threads at once, each for its own agent
// "<id>-<n>", between stations drawn (fixed --seed) from --stations FILE, starting at
// --start-ns plus up to --spread-s seconds, holding the destination --dwell-s seconds.
// Prints one JSON line per reply; exit 0 when every request got a reply, 1 otherwise.

#include <atomic>
#include <fstream>
#include <iostream>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "drover/common/clock.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/service_client.hpp"
#include "routing.h"

int main(int argc, char** argv) {
  using namespace drover;
  std::uint32_t domain = 0;
  std::string id;
  std::string stations_file;
  int count = 50;
  int threads = 4;
  std::uint64_t seed = 1;
  TimeNs start_ns = 0;
  double spread_s = 60;
  double dwell_s = 5;
  CLI::App app{"route service test client"};
  app.add_option("--domain", domain)->required();
  app.add_option("--id", id)->required();
  app.add_option("--stations", stations_file)->required();
  app.add_option("--count", count);
  app.add_option("--threads", threads);
  app.add_option("--seed", seed);
  app.add_option("--start-ns", start_ns)->required();
  app.add_option("--spread-s", spread_s);
  app.add_option("--dwell-s", dwell_s);
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> stations;
  std::ifstream in(stations_file);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) stations.push_back(line);
  }
  if (stations.size() < 2) {
    std::cerr << "error: " << stations_file << ": fewer than two stations\n";
    return 2;
  }
  // Every request is drawn up front, so the set does not depend on thread timing.
  std::mt19937_64 random(seed);
  std::vector<msg::RouteRequest> requests;
  for (int n = 0; n < count; ++n) {
    std::uniform_int_distribution<std::size_t> pick(0, stations.size() - 1);
    const std::size_t from = pick(random);
    std::size_t to = pick(random);
    while (to == from) to = pick(random);
    msg::RouteRequest request;
    request.agent(id + "-" + std::to_string(n));
    request.real(true);
    request.vehicle().id(request.agent());
    request.vehicle().max_speed(1.0);
    request.vehicle().acceleration(1.0);
    request.vehicle().deceleration(1.0);
    request.vehicle().length(1.0);
    request.vehicle().width(1.0);
    request.start(stations[from]);
    request.start_time(start_ns + static_cast<TimeNs>(std::uniform_real_distribution<double>(0, spread_s)(random) * 1e9));
    msg::RouteStop stop;
    stop.vertex(stations[to]);
    stop.has_dwell(true);
    stop.dwell(seconds_to_ns(dwell_s));
    request.stops().push_back(stop);
    requests.push_back(std::move(request));
  }

  drover::dds::ParticipantOptions options;
  options.domain_id = domain;
  options.agent_id = id;
  auto participant = drover::dds::Participant::create(options);
  if (!participant) {
    std::cerr << "error: " << participant.error().message << "\n";
    return 1;
  }
  int exit_code = 0;
  {
    auto client = drover::dds::ServiceClient<msg::RouteRequest, msg::RouteReply>::create(**participant, "routing", "route");
    if (!client) {
      std::cerr << "error: " << client.error().message << "\n";
      return 1;
    }
    std::atomic<std::size_t> next{0};
    std::atomic<bool> all_answered{true};
    std::mutex out_mutex;
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t) {
      workers.emplace_back([&] {
        for (std::size_t i = next++; i < requests.size(); i = next++) {
          auto reply = (*client)->call(requests[i], std::chrono::seconds(60));
          nlohmann::json line{{"agent", requests[i].agent()}};
          if (!reply) {
            all_answered = false;
            line["answered"] = false;
            line["message"] = reply.error().message;
          } else {
            line["answered"] = true;
            line["routing_agent"] = reply->header().responder();
            line["code"] = static_cast<int>(reply->error().code());
            line["message"] = reply->error().message();
            line["failure"] = reply->failure();
            line["route"] = reply->route();
            line["steps"] = reply->steps().size();
            line["attempts"] = reply->attempts();
          }
          std::lock_guard lock(out_mutex);
          std::cout << line.dump() << std::endl;
        }
      });
    }
    for (auto& worker : workers) worker.join();
    if (!all_answered) exit_code = 1;
  }
  return exit_code;
}

#pragma once
// Shared helpers of the DDS layer's multi-process tests. Every test uses its own domain id
// (100..199) so that tests running at the same time never see each other.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drover/dds/participant.hpp"
#include "tests/agents/child_process.hpp"

namespace drover::test {

/// Generous bound for anything discovery must achieve on a loaded 2-core machine.
inline constexpr std::chrono::milliseconds kDiscoveryTimeout{20000};

/// Starts dds_test_peer on `domain` as agent `id` with extra arguments (--echo,
/// --heartbeat KIND, --owns X).
inline std::optional<ChildProcess> spawn_peer(std::uint32_t domain, const std::string& id,
                                              const std::vector<std::string>& extra) {
  std::vector<std::string> args{"--domain", std::to_string(domain), "--id", id};
  args.insert(args.end(), extra.begin(), extra.end());
  return ChildProcess::spawn(binary_path("dds_test_peer"), args);
}

/// A participant of the test process itself.
inline std::unique_ptr<dds::Participant> make_participant(std::uint32_t domain, const std::string& id) {
  dds::ParticipantOptions options;
  options.domain_id = domain;
  options.agent_id = id;
  auto participant = dds::Participant::create(options);
  EXPECT_TRUE(participant.has_value()) << (participant ? "" : participant.error().message);
  return participant ? std::move(*participant) : nullptr;
}

}  // namespace drover::test

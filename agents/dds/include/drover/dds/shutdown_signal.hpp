#pragma once
// Clean shutdown of agents on SIGINT / SIGTERM: main installs the handlers first, builds
// its DDS entities, waits for shutdown, then destroys them and returns 0.
//
//   install_shutdown_handlers();
//   ... create participant, servers, heartbeat ...
//   wait_for_shutdown();
//   ... destroy them in reverse order ...
//   return 0;
//
// A second SIGINT / SIGTERM terminates the process at once (an agent stuck in shutdown).

#include <chrono>

#include "drover/common/result.hpp"

namespace drover::dds {

/// Installs the SIGINT and SIGTERM handlers (idempotent).
/// \return success, or io when the handlers or their pipe cannot be set up.
Status install_shutdown_handlers();

/// Requests shutdown as a signal would (a tool that is done, a test).
void request_shutdown() noexcept;

/// Whether shutdown has been requested.
bool shutdown_requested() noexcept;

/// Blocks until shutdown is requested.
void wait_for_shutdown() noexcept;

/// Blocks until shutdown is requested or `timeout` passes (at most about 24 days per call).
/// \return whether requested.
bool wait_for_shutdown(std::chrono::milliseconds timeout) noexcept;

}  // namespace drover::dds

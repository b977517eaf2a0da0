#include "drover/common/logging.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace drover {

std::shared_ptr<spdlog::logger> make_agent_logger(const std::string& agent_id,
                                                  const std::string& level) {
  auto logger = spdlog::get(agent_id);
  if (!logger) {
    logger = spdlog::stderr_color_mt(agent_id);
    logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %^%l%$: %v");
  }
  auto parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off") parsed = spdlog::level::info;
  logger->set_level(parsed);
  spdlog::set_default_logger(logger);
  return logger;
}

}  // namespace drover

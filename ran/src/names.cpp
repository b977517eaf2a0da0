// Stable lower-case names of the SDK's enums (wire format and tools), and the small
// lookups on VehicleStatus.

#include <algorithm>
#include <array>
#include <utility>

#include "drover/ran/commands.hpp"
#include "drover/ran/status.hpp"

namespace drover::ran {

namespace {

template <class Enum, std::size_t N>
const char* name_of(const std::array<std::pair<Enum, const char*>, N>& names, Enum value) {
  for (const auto& [candidate, name] : names) {
    if (candidate == value) return name;
  }
  return names.front().second;
}

template <class Enum, std::size_t N>
std::optional<Enum> value_of(const std::array<std::pair<Enum, const char*>, N>& names,
                             const std::string& text) {
  for (const auto& [value, name] : names) {
    if (text == name) return value;
  }
  return std::nullopt;
}

constexpr std::array<std::pair<ActionKind, const char*>, 4> kActionKinds{{
    {ActionKind::load, "load"},
    {ActionKind::unload, "unload"},
    {ActionKind::charge, "charge"},
    {ActionKind::custom, "custom"},
}};

constexpr std::array<std::pair<CommandState, const char*>, 6> kCommandStates{{
    {CommandState::accepted, "accepted"},
    {CommandState::running, "running"},
    {CommandState::finished, "finished"},
    {CommandState::failed, "failed"},
    {CommandState::cancelled, "cancelled"},
    {CommandState::rejected, "rejected"},
}};

constexpr std::array<std::pair<ErrorLevel, const char*>, 3> kErrorLevels{{
    {ErrorLevel::warning, "warning"},
    {ErrorLevel::recoverable, "recoverable"},
    {ErrorLevel::fatal, "fatal"},
}};

constexpr std::array<std::pair<LoadState, const char*>, 3> kLoadStates{{
    {LoadState::unknown, "unknown"},
    {LoadState::empty, "empty"},
    {LoadState::loaded, "loaded"},
}};

}  // namespace

const char* to_string(ActionKind kind) noexcept { return name_of(kActionKinds, kind); }
std::optional<ActionKind> action_kind_from_string(const std::string& name) noexcept {
  return value_of(kActionKinds, name);
}

const char* to_string(CommandState state) noexcept { return name_of(kCommandStates, state); }
std::optional<CommandState> command_state_from_string(const std::string& name) noexcept {
  return value_of(kCommandStates, name);
}

const char* to_string(ErrorLevel level) noexcept { return name_of(kErrorLevels, level); }
std::optional<ErrorLevel> error_level_from_string(const std::string& name) noexcept {
  return value_of(kErrorLevels, name);
}

const char* to_string(LoadState state) noexcept { return name_of(kLoadStates, state); }
std::optional<LoadState> load_state_from_string(const std::string& name) noexcept {
  return value_of(kLoadStates, name);
}

const CommandProgress* VehicleStatus::find_command(const CommandId& id) const {
  const auto found = std::find_if(commands.begin(), commands.end(),
                                  [&](const CommandProgress& c) { return c.id == id; });
  return found == commands.end() ? nullptr : &*found;
}

bool VehicleStatus::has_error(const std::string& code) const {
  return std::any_of(errors.begin(), errors.end(),
                     [&](const VehicleError& e) { return e.code == code; });
}

bool VehicleStatus::performs(const std::string& action) const {
  return actions.empty() || std::find(actions.begin(), actions.end(), action) != actions.end();
}

}  // namespace drover::ran

#include "drover/launcher/station_picker.hpp"

namespace drover::launcher {

StationPicker::StationPicker(std::vector<std::string> stations, std::uint64_t seed)
    : stations_(std::move(stations)), random_(seed) {}

std::pair<std::string, std::string> StationPicker::next() {
  // Drawn with explicit modular arithmetic rather than std::uniform_int_distribution, whose
  // sequence differs between standard libraries: a seed gives the same orders everywhere.
  const std::uint64_t count = stations_.size();
  const std::uint64_t from = random_() % count;
  const std::uint64_t to = (from + 1 + random_() % (count - 1)) % count;
  return {stations_[from], stations_[to]};
}

}  // namespace drover::launcher

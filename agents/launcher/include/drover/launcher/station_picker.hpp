#pragma once
// Picks the two stations of a random transport order, like openTCS's continuous-load
// plugin: a pick-up and a different drop-off, drawn uniformly from the stations given.
// Seeded, so a run's sequence of picks is reproducible.

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace drover::launcher {

class StationPicker {
 public:
  /// \pre stations.size() >= 2 and the ids are distinct.
  StationPicker(std::vector<std::string> stations, std::uint64_t seed);

  /// The next (pick-up, drop-off) pair; the two always differ.
  std::pair<std::string, std::string> next();

  const std::vector<std::string>& stations() const noexcept { return stations_; }

 private:
  std::vector<std::string> stations_;
  std::mt19937_64 random_;
};

}  // namespace drover::launcher

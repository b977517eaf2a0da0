#pragma once
// Two RANs for one vehicle (a simulator left running beside the real driver, two vehicles
// configured with one id) both publish its statuses and both take its commands. Their
// status writers alternate, A B A B ...; a RAN replaced by its next life (a restart) has
// a new writer too, but the old one never reports again. That difference is what this
// watch looks at. Until the old writer has been quiet for the window, a new one may be
// either: its statuses wait (the first status of a second RAN, taken, would put the
// vehicle where that RAN's vehicle is). One switch back (B A B) may be a late sample of
// the old writer; twins switch back again and again (A B A B).

#include <chrono>
#include <optional>
#include <utility>
#include <vector>

#include "drover/dds/sample_source.hpp"

namespace drover::ran {

/// Not thread-safe: the RanClient calls it under its mutex.
class TwinWriterWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// `window`: how long a writer counts as reporting after its last status (a RAN reports
  /// several times a second).
  explicit TwinWriterWatch(Clock::duration window) : window_(window) {}

  struct Verdict {
    enum class Kind {
      take,   ///< the only writer reporting
      wait,   ///< another writer reported within the window: a restart, or not yet known
      twins,  ///< the writers switched back twice within the window: two RANs report
    } kind = Kind::take;
    std::optional<dds::SampleSource> other;  ///< the other writer (wait, twins)
  };

  /// Notes a status written by `source` at `now`. \return what to make of it.
  Verdict observe(const dds::SampleSource& source, Clock::time_point now);

 private:
  Clock::duration window_;
  std::vector<std::pair<dds::SampleSource, Clock::time_point>> recent_;  ///< writer, last status
  std::optional<dds::SampleSource> last_;                                ///< writer of the last status
  std::optional<Clock::time_point> switched_back_;                       ///< the last switch back
  Clock::time_point twins_until_{};                                      ///< twins seen until then
};

}  // namespace drover::ran

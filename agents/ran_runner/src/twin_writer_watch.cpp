#include "drover/ran_runner/twin_writer_watch.hpp"

#include <algorithm>

namespace drover::ran {

TwinWriterWatch::Verdict TwinWriterWatch::observe(const dds::SampleSource& source, Clock::time_point now) {
  std::erase_if(recent_, [&](const auto& entry) { return now - entry.second > window_; });
  const auto known = std::find_if(recent_.begin(), recent_.end(), [&](const auto& entry) { return entry.first == source; });
  // Back to a writer that reported before another one: both are alive.
  if (last_ && !(*last_ == source) && known != recent_.end()) alternated_until_ = now + window_;
  if (known != recent_.end()) {
    known->second = now;
  } else {
    recent_.emplace_back(source, now);
  }
  last_ = source;
  for (const auto& [writer, seen] : recent_) {
    if (writer == source) continue;
    // Another writer within the window: `source` is the newer one unless they alternated.
    return Verdict{now < alternated_until_ ? Verdict::Kind::twins : Verdict::Kind::newcomer, writer};
  }
  return {};
}

}  // namespace drover::ran

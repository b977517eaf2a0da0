#include "drover/ran_runner/twin_writer_watch.hpp"

#include <algorithm>

namespace drover::ran {

TwinWriterWatch::Verdict TwinWriterWatch::observe(const dds::SampleSource& source, Clock::time_point now) {
  std::erase_if(recent_, [&](const auto& entry) { return now - entry.second > window_; });
  const auto known = std::find_if(recent_.begin(), recent_.end(), [&](const auto& entry) { return entry.first == source; });
  // Back to a writer that reported before another one, twice within the window: both are
  // alive (once may be a late sample of a replaced writer).
  if (last_ && !(*last_ == source) && known != recent_.end()) {
    if (switched_back_ && now - *switched_back_ <= window_) twins_until_ = now + window_;
    switched_back_ = now;
  }
  if (known != recent_.end()) {
    known->second = now;
  } else {
    recent_.emplace_back(source, now);
  }
  last_ = source;
  for (const auto& [writer, seen] : recent_) {
    if (writer == source) continue;
    // Another writer within the window: a replaced one, or a twin not yet known as one.
    return Verdict{now < twins_until_ ? Verdict::Kind::twins : Verdict::Kind::wait, writer};
  }
  return {};
}

}  // namespace drover::ran

#pragma once
// The launcher's terminal: every line an agent writes, prefixed with its agent id, the
// launcher's own notes, and a one-line progress. On a terminal the progress line stays at
// the bottom and is redrawn; otherwise it is printed as a plain line now and then, so that
// logs stay readable.

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace drover::launcher {

/// Cuts a byte stream into lines. Lines longer than kMaxLine are cut there.
class LineBuffer {
 public:
  static constexpr std::size_t kMaxLine = 64 * 1024;

  /// Appends `data` and calls `line(text)` (without the newline) for every completed line.
  template <class OnLine>
  void append(std::string_view data, OnLine&& line) {
    pending_.append(data);
    std::size_t start = 0;
    for (;;) {
      const auto newline = pending_.find('\n', start);
      if (newline == std::string::npos) break;
      line(std::string_view(pending_).substr(start, newline - start));
      start = newline + 1;
    }
    pending_.erase(0, start);
    while (pending_.size() >= kMaxLine) {
      line(std::string_view(pending_).substr(0, kMaxLine));
      pending_.erase(0, kMaxLine);
    }
  }

  /// At the end of the stream: a last line without newline, if any.
  template <class OnLine>
  void finish(OnLine&& line) {
    if (!pending_.empty()) line(std::string_view(pending_));
    pending_.clear();
  }

 private:
  std::string pending_;
};

/// Not thread-safe: the launcher writes from its supervising thread only.
class Console {
 public:
  /// \param plain_progress_period how often a progress line is printed when stderr is not
  ///        a terminal.
  explicit Console(std::chrono::milliseconds plain_progress_period = std::chrono::seconds(10));

  /// A line an agent wrote, to stdout or stderr as the agent did: "[id] text".
  void agent_line(bool to_stderr, std::string_view agent_id, std::string_view text);
  /// The launcher's own message, on stderr: "[launcher] text".
  void note(std::string_view text);
  /// The current progress (one line).
  void progress(std::string_view text);
  /// Removes the progress line from a terminal (before the summary).
  void end_progress();

 private:
  void clear_progress_line();
  void redraw_progress_line();

  bool terminal_;
  std::chrono::milliseconds plain_period_;
  std::chrono::steady_clock::time_point last_plain_{};
  std::string progress_;
  bool progress_shown_ = false;
};

}  // namespace drover::launcher

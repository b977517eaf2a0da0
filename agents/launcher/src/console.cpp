#include "drover/launcher/console.hpp"

#include <unistd.h>

namespace drover::launcher {

namespace {

void write_line(std::FILE* stream, std::string_view prefix, std::string_view text) {
  std::fwrite(prefix.data(), 1, prefix.size(), stream);
  std::fwrite(text.data(), 1, text.size(), stream);
  std::fputc('\n', stream);
}

}  // namespace

Console::Console(std::chrono::milliseconds plain_progress_period)
    : terminal_(::isatty(STDERR_FILENO) == 1), plain_period_(plain_progress_period) {}

void Console::agent_line(bool to_stderr, std::string_view agent_id, std::string_view text) {
  clear_progress_line();
  const std::string prefix = "[" + std::string(agent_id) + "] ";
  std::FILE* stream = to_stderr ? stderr : stdout;
  write_line(stream, prefix, text);
  std::fflush(stream);
  redraw_progress_line();
}

void Console::note(std::string_view text) {
  clear_progress_line();
  write_line(stderr, "[launcher] ", text);
  std::fflush(stderr);
  redraw_progress_line();
}

void Console::progress(std::string_view text) {
  progress_ = text;
  if (terminal_) {
    clear_progress_line();
    redraw_progress_line();
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (now - last_plain_ >= plain_period_) {
    last_plain_ = now;
    write_line(stderr, "[launcher] ", progress_);
    std::fflush(stderr);
  }
}

void Console::end_progress() {
  clear_progress_line();
  progress_.clear();
}

void Console::clear_progress_line() {
  if (!terminal_ || !progress_shown_) return;
  std::fputs("\r\033[K", stderr);
  progress_shown_ = false;
}

void Console::redraw_progress_line() {
  if (!terminal_ || progress_.empty()) return;
  std::fputs(progress_.c_str(), stderr);
  std::fflush(stderr);
  progress_shown_ = true;
}

}  // namespace drover::launcher

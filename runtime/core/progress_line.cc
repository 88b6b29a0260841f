#include "runtime/core/progress_line.h"

#include <unistd.h>

#include <iostream>

namespace autoshovel::core {

bool IsTerminal(const std::ostream& stream) {
  if (&stream == &std::cerr || &stream == &std::clog) return ::isatty(STDERR_FILENO) == 1;
  if (&stream == &std::cout) return ::isatty(STDOUT_FILENO) == 1;
  return false;
}

ProgressLine::ProgressLine(std::ostream& stream) : ProgressLine(stream, IsTerminal(stream)) {}

ProgressLine::ProgressLine(std::ostream& stream, bool terminal)
    : stream_(stream), terminal_(terminal) {}

void ProgressLine::Update(const std::string& text, bool news) {
  const auto now = std::chrono::steady_clock::now();
  if (terminal_) {
    std::string line = "\r" + text;
    if (text.size() < shown_length_) line.append(shown_length_ - text.size(), ' ');
    shown_length_ = text.size();
    stream_ << line << std::flush;
    return;
  }
  if (!news && any_line_ && now - last_line_ < heartbeat) return;
  stream_ << text << '\n' << std::flush;
  last_line_ = now;
  any_line_ = true;
}

void ProgressLine::Finish(const std::string& text) {
  if (terminal_) {
    Update(text);
    stream_ << '\n' << std::flush;
    shown_length_ = 0;
    return;
  }
  stream_ << text << '\n' << std::flush;
  last_line_ = std::chrono::steady_clock::now();
  any_line_ = true;
}

}  // namespace autoshovel::core

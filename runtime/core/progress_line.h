// Progress of long work on a stream, written as a person or a log file wants it. On a terminal
// the line is rewritten in place (`\r`); anywhere else (a file, a pipe, CI's log) each update is
// a whole line of its own, and only when there is news or a minute has passed: issue 38 found a
// week-long campaign's progress written to a file as one 100 KB line of `\r` updates.
#pragma once

#include <chrono>
#include <ostream>
#include <string>

namespace autoshovel::core {

/// Whether `stream` is std::cout or std::cerr and that descriptor is a terminal. Any other stream
/// (a file, a string stream in a test) is not.
bool IsTerminal(const std::ostream& stream);

class ProgressLine {
 public:
  /// `terminal`: rewrite in place; by default IsTerminal(stream).
  explicit ProgressLine(std::ostream& stream);
  ProgressLine(std::ostream& stream, bool terminal);

  /// Shows `text`. `news`: something changed (a count moved). Off a terminal a line is written
  /// only for news or when `heartbeat` has passed since the last line, so a stalled job still
  /// shows it is alive.
  void Update(const std::string& text, bool news = true);

  /// The last update, always written, and the line ended.
  void Finish(const std::string& text);

  bool terminal() const { return terminal_; }

  std::chrono::seconds heartbeat{60};

 private:
  std::ostream& stream_;
  bool terminal_;
  std::size_t shown_length_ = 0;  // of the line on the terminal, to blank a longer old one
  std::chrono::steady_clock::time_point last_line_{};
  bool any_line_ = false;
};

}  // namespace autoshovel::core

// Input diagnostics: every problem found in a description, scenario or config file is reported
// as `file:line:column: key.path: message`, and all problems of a file are collected before
// anything runs on it (STYLE.md, "Errors").
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::core {

/// A place in an input file. Line and column are 1-based (yaml-cpp's marks are 0-based: the
/// readers add 1). Line 0 means "the file as a whole" (e.g. it cannot be opened).
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;

  std::string ToString() const;
};

/// An error refuses the file; a warning (a value outside physical ranges that still loads, see
/// runtime/model/plausibility.h) is reported and the file is used.
enum class Severity { kError, kWarning };

/// One problem in an input file.
struct Diagnostic {
  SourceLocation where;
  std::string key_path;  ///< e.g. `arm.links[1].length`; empty for file-level problems
  std::string message;   ///< what is wrong and what was expected
  Severity severity = Severity::kError;

  /// `file:line:column: key.path: message` on one line; a warning reads
  /// `file:line:column: warning: key.path: message` (the compilers' form).
  std::string ToString() const;
};

/// Writes each warning once per process to standard error (a description loaded by every job
/// of a campaign warns once).
void ReportWarnings(const std::vector<Diagnostic>& warnings);

/// Collects diagnostics while a file is read, so that one run reports every problem.
class DiagnosticSink {
 public:
  void Add(SourceLocation where, std::string key_path, std::string message);
  bool empty() const { return diagnostics_.empty(); }
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

  /// Throws InputError with everything collected, if anything was.
  void ThrowIfAny() const;

 private:
  std::vector<Diagnostic> diagnostics_;
};

/// Refuses an input with the one problem found at `where` (a reader that stops at the first).
[[noreturn]] void RefuseInput(SourceLocation where, std::string message);

/// Thrown when an input file is refused. `what()` holds one line per diagnostic.
class InputError : public std::runtime_error {
 public:
  explicit InputError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

}  // namespace autoshovel::core

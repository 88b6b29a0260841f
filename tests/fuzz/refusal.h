// What a refusal of bad input must look like, shared by the fuzz targets (which abort on a
// violation: a finding) and the regression test (which expects none): core::InputError with at
// least one diagnostic, each naming the file that was read, with a message, and with a line that
// exists in that file, or 0 for "the file as a whole" (core/diagnostics.h) — or one past the
// last line, where a truncated file's missing line would be.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "runtime/core/diagnostics.h"

namespace autoshovel::fuzz {

/// Lines as a line reader counts them: the last one need not end in '\n'.
inline int CountLines(std::string_view bytes) {
  const auto newlines = static_cast<int>(std::count(bytes.begin(), bytes.end(), '\n'));
  return newlines + (!bytes.empty() && bytes.back() != '\n' ? 1 : 0);
}

/// "" when `error` is a located refusal of `path` (a file of `lines` lines); else what is wrong.
inline std::string RefusalProblem(const core::InputError& error, const std::string& path,
                                  int lines) {
  if (error.diagnostics().empty()) {
    return "InputError without diagnostics: " + std::string(error.what());
  }
  for (const core::Diagnostic& d : error.diagnostics()) {
    if (d.where.file != path) return "the diagnostic names another file: " + d.ToString();
    if (d.where.line < 0 || d.where.line > lines + 1) {
      return "line " + std::to_string(d.where.line) + " of a file of " + std::to_string(lines) +
             " lines: " + d.ToString();
    }
    if (d.message.empty()) return "a diagnostic without a message: " + d.ToString();
  }
  return "";
}

/// For the fuzz targets: a refusal that is not located is a finding, reported like a crash.
inline void AbortUnlessLocated(const core::InputError& error, const std::string& path,
                               std::string_view bytes) {
  const std::string problem = RefusalProblem(error, path, CountLines(bytes));
  if (problem.empty()) return;
  std::fprintf(stderr, "unlocated refusal: %s\n", problem.c_str());
  std::abort();
}

}  // namespace autoshovel::fuzz

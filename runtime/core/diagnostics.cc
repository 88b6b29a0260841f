#include "runtime/core/diagnostics.h"

#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace autoshovel::core {
namespace {

std::string JoinLines(const std::vector<Diagnostic>& diagnostics) {
  std::ostringstream out;
  for (std::size_t i = 0; i < diagnostics.size(); ++i) {
    if (i > 0) out << '\n';
    out << diagnostics[i].ToString();
  }
  return out.str();
}

}  // namespace

std::string SourceLocation::ToString() const {
  if (line <= 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string Diagnostic::ToString() const {
  std::string text = where.ToString() + ": ";
  if (severity == Severity::kWarning) text += "warning: ";
  if (!key_path.empty()) text += key_path + ": ";
  return text + message;
}

void ReportWarnings(const std::vector<Diagnostic>& warnings) {
  static std::mutex mutex;
  static std::set<std::string> reported;
  const std::lock_guard<std::mutex> lock(mutex);
  for (const Diagnostic& warning : warnings) {
    const std::string line = warning.ToString();
    if (reported.insert(line).second) std::cerr << line << '\n';
  }
}

void DiagnosticSink::Add(SourceLocation where, std::string key_path, std::string message) {
  diagnostics_.push_back({std::move(where), std::move(key_path), std::move(message)});
}

void DiagnosticSink::ThrowIfAny() const {
  if (!diagnostics_.empty()) throw InputError(diagnostics_);
}

void RefuseInput(SourceLocation where, std::string message) {
  DiagnosticSink sink;
  sink.Add(std::move(where), "", std::move(message));
  sink.ThrowIfAny();
  throw std::logic_error("RefuseInput: the sink did not throw");  // unreachable
}

InputError::InputError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(JoinLines(diagnostics)), diagnostics_(std::move(diagnostics)) {}

}  // namespace autoshovel::core

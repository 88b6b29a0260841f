// `autoshovel describe MACHINE`: the derived quantities of a machine, for a field engineer.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct DescribeOptions {
  std::string machine;  ///< name or path
  std::string models_dir;
  bool show_estimated = false;
};

/// Prints the summary; returns a process exit code (diagnostics on `err`).
int RunDescribe(const DescribeOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app

// `autoshovel describe MACHINE`: the derived quantities of a machine, for a field engineer.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::app {

struct DescribeOptions {
  std::string machine;  ///< name or path
  std::string models_dir;
  bool show_estimated = false;
  std::vector<std::string> overlays;  ///< identified values applied on top
};

/// Prints the summary; returns a process exit code (diagnostics on `err`).
int RunDescribe(const DescribeOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app

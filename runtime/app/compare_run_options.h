// The run options every single-cycle comparison (compare table4 | table5 | audit) starts from:
// one cycle, no figures, the compare command's scoop profile, predictor and machine.
#pragma once

#include "runtime/app/compare_command.h"
#include "runtime/app/shovel_run.h"

namespace autoshovel::app {

ShovelRunOptions SingleCycleRunOptions(const CompareOptions& options);

}  // namespace autoshovel::app

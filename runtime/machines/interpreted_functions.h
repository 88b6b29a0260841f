// generated::MachineFunctions evaluated by the interpreted reference model
// (runtime/model/interpreted_model.h): what a machine runs on when it has no compiled code and
// no C++ compiler is present to build any. Slower than generated code (every call walks the
// description; the plant Jacobian is automatic differentiation), equal to it within rounding.
#pragma once

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::machines {

/// Descriptions that can be interpreted at once in one process: MachineFunctions holds plain
/// function pointers, so each description gets one of a fixed number of slots.
inline constexpr int kInterpretedSlots = 16;

/// The functions of `machine` (copied: the caller's description may go away). The same
/// description (name, hash and overlays) gives the same table every time; the table lives as
/// long as the process. Throws std::runtime_error when every slot is taken.
const generated::MachineFunctions& InterpretedFunctions(const model::MachineDescription& machine);

}  // namespace autoshovel::machines

// Fuzz target: the machine description loader (YAML -> model::MachineDescription, validation
// included). Materials come from models/materials, so a mutated description is checked against
// real materials; LoadMachineDescription documents core::InputError as its only refusal.
#include <cstddef>
#include <cstdint>

#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".yaml");
  model::LoadOptions options;
  options.materials_dir = AUTOSHOVEL_SOURCE_DIR "/models/materials";
  try {
    model::LoadMachineDescription(path, options);
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

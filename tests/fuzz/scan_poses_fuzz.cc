// Fuzz target: the scan poses file of `map --cloud --poses` (runtime/perception/scan/
// scan_poses.h). It either reads the file, every pose a finite rigid transform, or refuses it
// with a located core::InputError.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "runtime/core/diagnostics.h"
#include "runtime/perception/scan/scan_poses.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".txt");
  try {
    for (const auto& [name, T] : perception::ReadScanPoses(path)) {
      if (name.empty() || !T.matrix().allFinite()) std::abort();
    }
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

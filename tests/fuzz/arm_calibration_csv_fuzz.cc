// Fuzz target: the arm calibration measurement CSV (identification/calibration/
// arm_calibration_csv.h), read for a wheel loader's links (boom, bucket). Its only documented
// refusal is core::InputError.
#include <cstddef>
#include <cstdint>

#include "identification/calibration/arm_calibration_csv.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".csv");
  try {
    identification::ReadArmCalibrationCsv(path, {"boom", "bucket"});
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

// Fuzz target: the hydraulic identification log reader (identification/hydraulics/log_reader.h).
// Every input is read in both formats of hydraulic_log_formats.h. Its only documented refusal
// is core::InputError.
#include <cstddef>
#include <cstdint>

#include "identification/hydraulics/log_reader.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/hydraulic_log_formats.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  static const std::vector<identification::LogFormat> formats = fuzz::HydraulicLogFormats();
  const std::string path = fuzz::WriteInput(data, size, ".csv");
  for (const identification::LogFormat& format : formats) {
    try {
      identification::ReadHydraulicLog(path, format);
    } catch (const core::InputError& e) {
      fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
    }
  }
  return 0;
}

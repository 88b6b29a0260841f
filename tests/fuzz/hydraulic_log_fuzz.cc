// Fuzz target: the hydraulic identification log reader (identification/hydraulics/log_reader.h)
// with ControlDesk exports and column expressions (issue 40). Every input is read in each format
// hydraulic_log_formats.h gives for it (ordinary logs by default names, by position and by
// expressions; ControlDesk exports by names, paths and numbers in expressions; and, when the
// input opens with `# columns: SPEC`, by that map, so that expressions themselves are fuzzed).
// Its only documented refusal is core::InputError.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "identification/hydraulics/log_reader.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/hydraulic_log_formats.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string path = fuzz::WriteInput(data, size, ".csv");
  // A `# columns:` map that ParseColumnsSpec refuses is refused naming `--columns`, with a word.
  if (const std::optional<std::string> spec = fuzz::ColumnsSpecOf(bytes)) {
    try {
      identification::ParseColumnsSpec(*spec);
    } catch (const core::InputError& e) {
      if (e.diagnostics().size() != 1 || e.diagnostics()[0].where.file != "--columns" ||
          e.diagnostics()[0].message.empty()) {
        std::fprintf(stderr, "--columns refusal without its source: %s\n", e.what());
        std::abort();
      }
    }
  }
  for (const identification::LogFormat& format : fuzz::HydraulicLogFormats(bytes)) {
    try {
      identification::ReadHydraulicLog(path, format);
    } catch (const core::InputError& e) {
      fuzz::AbortUnlessLocated(e, path, bytes);
    }
  }
  return 0;
}

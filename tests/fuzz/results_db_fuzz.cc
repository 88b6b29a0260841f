// Fuzz target: the results database read back (runtime/results/results_db.h), as `report`,
// `train predictor DB` and a campaign's resume read it: opened read-only (schema and integrity
// checked), then every run, every cycle with its samples, and the crowding samples with their
// logged predictions (issue 41). Its only documented refusal is ResultsDbError; the seed is a
// one-cycle database, so mutations reach the column readers.
#include <cstddef>
#include <cstdint>

#include "runtime/results/results_db.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".sqlite");
  try {
    const results::ResultsDb db(path, results::ResultsDb::Access::kReadOnly);
    for (const results::RunInfo& run : db.Runs()) db.Cycles(run.run_id, /*with_samples=*/true);
    db.CrowdingSamples();
  } catch (const results::ResultsDbError&) {
    // Refused, naming the file: the reader's documented answer to a file it cannot trust.
  }
  return 0;
}

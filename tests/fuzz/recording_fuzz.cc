// Fuzz targets: the recording folder's tables and manifest (runtime/recording/recording_tables.h),
// one per file: RECORDING_TABLE 0 updates.csv, 1 frames.csv, 2 recording.yaml, 3 scoop.csv,
// 4 tip_path.csv. Each either reads
// the file, every number finite and every pose rigid, or refuses it with a located
// core::InputError.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/recording/recording_tables.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

#ifndef RECORDING_TABLE
#define RECORDING_TABLE 0
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = fuzz::WriteInput(data, size, RECORDING_TABLE == 2 ? ".yaml" : ".csv");
  try {
    if constexpr (RECORDING_TABLE == 0) {
      for (const recording::UpdateRow& u : recording::ParseUpdatesCsv(text, path)) {
        if (!std::isfinite(u.stamp) || !u.hinge_xy.allFinite() || !(u.tip_reach >= 0)) {
          std::abort();
        }
      }
    } else if constexpr (RECORDING_TABLE == 1) {
      for (const recording::FrameRow& f : recording::ParseFramesCsv(text, path)) {
        if (!f.T_world_sensor.matrix().allFinite() || f.file.empty() || f.file.front() == '/') {
          std::abort();
        }
        // No part of the path may leave the folder: none is "." or "..".
        std::size_t start = 0;
        while (start <= f.file.size()) {
          const std::size_t end = std::min(f.file.find('/', start), f.file.size());
          const std::string part = f.file.substr(start, end - start);
          if (part == "." || part == "..") std::abort();
          start = end + 1;
        }
      }
    } else if constexpr (RECORDING_TABLE == 3) {
      for (const recording::DecisionRow& d : recording::ParseScoopCsv(text, path)) {
        if (!std::isfinite(d.time) || !d.hinge_xy.allFinite() || !(d.path_points >= 1)) {
          std::abort();
        }
      }
    } else if constexpr (RECORDING_TABLE == 4) {
      for (const recording::TipPoint& t : recording::ParseTipPathCsv(text, path)) {
        if (!t.p.allFinite()) std::abort();
      }
    } else {
      const recording::Manifest m = recording::ReadManifest(path);
      if (!(m.map_resolution > 0) || !m.map_center.allFinite() || m.machine_file.empty()) {
        std::abort();
      }
    }
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, text);
  }
  return 0;
}

// Fuzz target: the PCD reader (identification/camera_lidar/point_cloud_io.h): the project's
// header check, then pcl::io's decoding of ascii, binary and binary_compressed data. Its only
// documented refusal is core::InputError. A point bound exercises the sampling after decoding.
// Built a second time as fuzz_ply with CLOUD_EXTENSION ".ply": the PLY reader (ply_io.h).
#include <pcl/console/print.h>

#include <cstddef>
#include <cstdint>

#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // pcl::io prints its own complaints; the reader's InputError is what is checked.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
#ifndef CLOUD_EXTENSION
#define CLOUD_EXTENSION ".pcd"
#endif
  const std::string path = fuzz::WriteInput(data, size, CLOUD_EXTENSION);
  try {
    identification::ReadPointCloud(path, /*max_points=*/64);
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

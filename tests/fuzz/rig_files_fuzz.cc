// Fuzz targets: the standalone rig's text files (identification/camera_lidar/rig_files.h), one
// target per reader, chosen by RIG_READER: 1 calib.txt, 2 an extrinsic matrix, 3 2D–3D
// correspondences. Each either reads the file or refuses it with a located core::InputError;
// an accepted extrinsic must be a finite rigid transform.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "identification/camera_lidar/rig_files.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

#ifndef RIG_READER
#error "RIG_READER must be 1 (calib.txt), 2 (extrinsic) or 3 (correspondences)"
#endif

namespace {

void CheckRigid(const Eigen::Isometry3d& T) {
  const double error = (T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm();
  if (!T.matrix().allFinite() || !(error < 1e-6)) {
    std::fprintf(stderr, "accepted a transform that is not rigid (|RᵀR − I| = %g)\n", error);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".txt");
  try {
#if RIG_READER == 1
    const identification::RigCalibrationFile file = identification::ReadCalibTxt(path);
    if (file.T_optical_lidar) CheckRigid(*file.T_optical_lidar);
    if (file.K && !file.K->allFinite()) std::abort();
#elif RIG_READER == 2
    CheckRigid(identification::ReadExtrinsic(path));
#else
    for (const auto& c : identification::ReadCorrespondences(path)) {
      if (!c.uv.allFinite() || !c.p_lidar.allFinite()) std::abort();
    }
#endif
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

// Fuzz target: the image header reader (identification/camera_lidar/image_header.h), which reads
// PNG and JPEG dimensions from untrusted files before OpenCV may decode them. Its only documented
// refusal is core::InputError, for the file as a whole (line 0); an accepted header must hold
// dimensions within the documented limit.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "identification/camera_lidar/image_header.h"
#include "runtime/core/diagnostics.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string path = fuzz::WriteInput(data, size, ".png");
  try {
    const identification::ImageHeader header = identification::ReadImageHeader(path);
    const auto pixels = static_cast<std::int64_t>(header.width) * header.height;
    if (header.width <= 0 || header.height <= 0 || pixels > identification::kMaxImagePixels) {
      std::fprintf(stderr, "accepted an image of %d x %d px\n", header.width, header.height);
      std::abort();
    }
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, {reinterpret_cast<const char*>(data), size});
  }
  return 0;
}

// Image dimensions from the file's first bytes, before any decoding.
//
// cv::imread allocates the whole bitmap a header announces: a 1.1 MB PNG whose IHDR says
// 20000 x 20000 px took 1.3 GB before its size could be compared with the intrinsics. The readers
// of camera images and mask PNGs therefore read the header here first, refuse what is too large
// or not the size they expect, and only then decode (docs/camera_lidar_calibration.md, "Input
// limits"). Only PNG and JPEG are read (the formats the camera-LiDAR inputs may have):
// - PNG: the signature, then the IHDR chunk, which the format requires first (width, height);
// - JPEG: SOI, then marker segments up to the first start-of-frame (SOF0–SOF15 except DHT, JPG
//   and DAC), whose frame header holds height and width.
// Malformed headers throw core::InputError naming the file (line 0: a binary file has no lines):
//   frame.png: PNG header says 20000 x 20000 px (400 Mpx), more than the 100 Mpx limit
//   frame.jpg: JPEG: no frame header (SOFn) before the scan data
// No dependency beyond core: the libFuzzer target tests/fuzz/image_header_fuzz.cc builds it alone.
#pragma once

#include <cstdint>
#include <string>

namespace autoshovel::identification {

/// The most pixels an input image may have: 100 Mpx, ten times a 4K frame and about 300 times
/// the project's cameras (480 x 383 and 1280 x 720 px). Decoded as 8-bit BGR that is 300 MB.
inline constexpr std::int64_t kMaxImagePixels = 100'000'000;

struct ImageHeader {
  std::string format;  ///< "PNG" or "JPEG"
  int width = 0;       ///< [px], > 0
  int height = 0;      ///< [px], > 0
};

/// Reads the format and dimensions without decoding. Throws core::InputError naming `path` for a
/// file that cannot be opened, is not PNG or JPEG, has a truncated or malformed header, a zero
/// dimension, or more than kMaxImagePixels pixels.
ImageHeader ReadImageHeader(const std::string& path);

/// "W x H px".
std::string ImageSizeText(int width, int height);

}  // namespace autoshovel::identification

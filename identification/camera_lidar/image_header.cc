#include "identification/camera_lidar/image_header.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {

namespace {

[[noreturn]] void Fail(const std::string& file, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, 0, 0}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

std::string Hex(int byte) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", byte & 0xFF);
  return text;
}

std::uint32_t BigEndian(const unsigned char* p, int bytes) {
  std::uint32_t value = 0;
  for (int i = 0; i < bytes; ++i) value = (value << 8) | p[i];
  return value;
}

// Bounds-checked reads of the first bytes: every offset is compared with the file's size, so a
// header that points past the end is "truncated", never a read of what is not there.
class Bytes {
 public:
  Bytes(std::ifstream& in, std::int64_t size) : in_(in), size_(size) {}
  std::int64_t size() const { return size_; }

  bool Read(std::int64_t offset, unsigned char* out, int count) {
    if (offset < 0 || offset + count > size_) return false;
    in_.clear();
    in_.seekg(offset);
    return static_cast<bool>(in_.read(reinterpret_cast<char*>(out), count));
  }

 private:
  std::ifstream& in_;
  std::int64_t size_;
};

void CheckDimensions(const std::string& path, const ImageHeader& header, std::uint32_t width,
                     std::uint32_t height) {
  // PNG allows up to 2^31 - 1 per side, JPEG 65535; 0 is invalid in both.
  if (width == 0 || height == 0 || width > 0x7FFFFFFFu || height > 0x7FFFFFFFu) {
    Fail(path, header.format + " header says " + std::to_string(width) + " x " +
                   std::to_string(height) + " px: not a valid image size");
  }
  const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
  if (pixels > kMaxImagePixels) {
    Fail(path, header.format + " header says " + std::to_string(width) + " x " +
                   std::to_string(height) + " px (" + std::to_string(pixels / 1'000'000) +
                   " Mpx), more than the " + std::to_string(kMaxImagePixels / 1'000'000) +
                   " Mpx an input image may have: not decoded");
  }
}

ImageHeader ReadPng(const std::string& path, Bytes& bytes) {
  ImageHeader header{"PNG", 0, 0};
  // The signature (8 bytes), then IHDR: length 13, type, width, height, ... (PNG spec 11.2.2).
  std::array<unsigned char, 16> chunk{};
  if (!bytes.Read(8, chunk.data(), 16)) {
    Fail(path, "PNG: truncated: the file ends before the IHDR chunk (" +
                   std::to_string(bytes.size()) + " bytes)");
  }
  const std::uint32_t length = BigEndian(chunk.data(), 4);
  const std::string type(reinterpret_cast<const char*>(chunk.data() + 4), 4);
  if (type != "IHDR") Fail(path, "PNG: the first chunk is not IHDR");
  if (length != 13) {
    Fail(path, "PNG: the IHDR chunk has " + std::to_string(length) + " bytes, not 13");
  }
  const std::uint32_t width = BigEndian(chunk.data() + 8, 4);
  const std::uint32_t height = BigEndian(chunk.data() + 12, 4);
  CheckDimensions(path, header, width, height);
  header.width = static_cast<int>(width);
  header.height = static_cast<int>(height);
  return header;
}

bool IsStartOfFrame(int marker) {
  // SOF0–SOF15 are 0xC0–0xCF, except DHT (0xC4), JPG (0xC8) and DAC (0xCC).
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}

ImageHeader ReadJpeg(const std::string& path, Bytes& bytes) {
  ImageHeader header{"JPEG", 0, 0};
  std::int64_t at = 2;  // after SOI
  unsigned char b[5];
  // Each step moves at least two bytes forward: the loop ends within the file's size.
  while (true) {
    if (!bytes.Read(at, b, 1)) {
      Fail(path, "JPEG: truncated: no frame header (SOFn) in the file's " +
                     std::to_string(bytes.size()) + " bytes");
    }
    if (b[0] != 0xFF) {
      Fail(path, "JPEG: byte " + std::to_string(at) + " is " + Hex(b[0]) +
                     " where a marker (0xFF) belongs");
    }
    int marker = 0xFF;
    while (marker == 0xFF) {  // fill bytes
      ++at;
      if (!bytes.Read(at, b, 1)) Fail(path, "JPEG: truncated inside a marker");
      marker = b[0];
    }
    ++at;                                                                // past the marker code
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length
    if (marker == 0xDA || marker == 0xD9 || marker == 0xD8 || marker == 0x00) {
      Fail(path, "JPEG: marker " + Hex(marker) + " at byte " + std::to_string(at - 2) +
                     " before any frame header (SOFn)");
    }
    if (!bytes.Read(at, b, 2)) Fail(path, "JPEG: truncated inside the " + Hex(marker) + " segment");
    const std::uint32_t length = BigEndian(b, 2);
    if (length < 2) {
      Fail(path, "JPEG: segment " + Hex(marker) + " at byte " + std::to_string(at - 2) +
                     " has length " + std::to_string(length) + " (at least 2)");
    }
    if (at + length > bytes.size()) {
      Fail(path, "JPEG: truncated: segment " + Hex(marker) + " at byte " + std::to_string(at - 2) +
                     " has " + std::to_string(length) + " bytes, the file ends " +
                     std::to_string(bytes.size() - at) + " bytes after its length");
    }
    if (IsStartOfFrame(marker)) {
      // Frame header: length (2), precision (1), height (2), width (2), ... (ITU T.81 B.2.2).
      if (length < 8 || !bytes.Read(at + 2, b, 5)) {
        Fail(path, "JPEG: truncated frame header (" + Hex(marker) + ")");
      }
      const std::uint32_t height = BigEndian(b + 1, 2);
      const std::uint32_t width = BigEndian(b + 3, 2);
      if (height == 0) {
        Fail(path, "JPEG: frame height 0 (set later by a DNL marker) is not supported");
      }
      CheckDimensions(path, header, width, height);
      header.width = static_cast<int>(width);
      header.height = static_cast<int>(height);
      return header;
    }
    at += length;
  }
}

}  // namespace

std::string ImageSizeText(int width, int height) {
  return std::to_string(width) + " x " + std::to_string(height) + " px";
}

ImageHeader ReadImageHeader(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    Fail(path, std::filesystem::exists(path, error) ? "not a regular file" : "no such image file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot open the image");
  in.seekg(0, std::ios::end);
  const std::int64_t size = static_cast<std::int64_t>(in.tellg());
  if (size < 0) Fail(path, "cannot read the image (not a regular file?)");
  Bytes bytes(in, size);
  std::array<unsigned char, 8> magic{};
  const bool read = bytes.Read(0, magic.data(), 8);
  static constexpr std::array<unsigned char, 8> kPng = {0x89, 'P',  'N',  'G',
                                                        '\r', '\n', 0x1A, '\n'};
  if (read && magic == kPng) return ReadPng(path, bytes);
  if (size >= 2 && bytes.Read(0, magic.data(), 2) && magic[0] == 0xFF && magic[1] == 0xD8) {
    return ReadJpeg(path, bytes);
  }
  Fail(path, size == 0 ? "the image file is empty"
                       : "not a PNG or JPEG image (no PNG signature or JPEG SOI marker)");
}

}  // namespace autoshovel::identification

#include "identification/camera_lidar/ply_io.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/input_file.h"

namespace autoshovel::identification {

namespace {

[[noreturn]] void Fail(const std::string& file, int line, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, line, line > 0 ? 1 : 0}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

enum class Format { kAscii, kLittle, kBig };

struct Property {
  std::string name;
  int size = 0;  // bytes in binary
  bool floating = false, is_signed = false;
};

// The size of a PLY scalar type, 0 when it is none.
int TypeSize(const std::string& type, bool& floating, bool& is_signed) {
  floating = type == "float" || type == "float32" || type == "double" || type == "float64";
  is_signed = floating || type == "char" || type == "int8" || type == "short" || type == "int16" ||
              type == "int" || type == "int32";
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

double Decode(const unsigned char* bytes, const Property& p, bool swap) {
  unsigned char b[8];
  std::memcpy(b, bytes, static_cast<std::size_t>(p.size));
  if (swap) std::reverse(b, b + p.size);
  if (p.floating) {
    if (p.size == 4) {
      float f;
      std::memcpy(&f, b, 4);
      return f;
    }
    double d;
    std::memcpy(&d, b, 8);
    return d;
  }
  switch (p.size) {
    case 1:
      return p.is_signed ? static_cast<double>(static_cast<std::int8_t>(b[0])) : b[0];
    case 2: {
      std::uint16_t v;
      std::memcpy(&v, b, 2);
      return p.is_signed ? static_cast<double>(static_cast<std::int16_t>(v)) : v;
    }
    default: {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return p.is_signed ? static_cast<double>(static_cast<std::int32_t>(v)) : v;
    }
  }
}

}  // namespace

sensors::PointCloud ReadPly(const std::string& path, PointCloudReadStats& stats) {
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Fail(path, 0, "cannot open the point cloud: " + why);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, 0, "cannot open the point cloud");
  std::string line;
  int line_number = 0;
  auto next_line = [&]() {
    if (!std::getline(in, line)) Fail(path, line_number + 1, "header ends before end_header");
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() > 4096) Fail(path, line_number, "header line longer than 4096 characters");
    std::istringstream words(line);
    std::vector<std::string> out;
    for (std::string w; words >> w;) out.push_back(w);
    return out;
  };
  if (next_line() != std::vector<std::string>{"ply"}) {
    Fail(path, 1, "not a PLY file (the first line must be 'ply')");
  }
  Format format = Format::kAscii;
  bool have_format = false, in_vertex = false, vertex_seen = false, after_vertex = false;
  long long count = -1;
  std::vector<Property> properties;
  int vertex_line = 0;
  while (true) {
    const std::vector<std::string> w = next_line();
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") Fail(path, line_number, "format: expected '<type> 1.0'");
      if (w[1] == "ascii") {
        format = Format::kAscii;
      } else if (w[1] == "binary_little_endian") {
        format = Format::kLittle;
      } else if (w[1] == "binary_big_endian") {
        format = Format::kBig;
      } else {
        Fail(path, line_number, "format: unknown '" + w[1].substr(0, 40) + "'");
      }
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) Fail(path, line_number, "element: expected 'element <name> <count>'");
      if (in_vertex) after_vertex = true;
      in_vertex = w[1] == "vertex";
      if (in_vertex) {
        if (vertex_seen || after_vertex) Fail(path, line_number, "element vertex: given twice");
        vertex_seen = true;
        vertex_line = line_number;
        char* end = nullptr;
        errno = 0;
        count = std::strtoll(w[2].c_str(), &end, 10);
        if (errno != 0 || *end != '\0' || count < 0) {
          Fail(path, line_number,
               "element vertex: count '" + w[2].substr(0, 40) + "' is not a number");
        }
        if (count > static_cast<long long>(kMaxCloudPoints)) {
          Fail(path, line_number,
               "element vertex: " + std::to_string(count) + " vertices, more than the " +
                   std::to_string(kMaxCloudPoints) + " a point cloud may have: not read");
        }
      } else if (!vertex_seen) {
        Fail(
            path, line_number,
            "element vertex: must be the first element (found '" + w[1].substr(0, 40) + "' first)");
      }
    } else if (w[0] == "property") {
      if (!in_vertex) continue;  // properties of later elements: ignored
      if (w.size() >= 2 && w[1] == "list") {
        Fail(path, line_number, "property list in the vertex element is not supported");
      }
      if (w.size() != 3) Fail(path, line_number, "property: expected 'property <type> <name>'");
      Property p;
      p.name = w[2];
      p.size = TypeSize(w[1], p.floating, p.is_signed);
      if (p.size == 0)
        Fail(path, line_number, "property: unknown type '" + w[1].substr(0, 40) + "'");
      properties.push_back(p);
    } else {
      Fail(path, line_number, "unknown header keyword '" + w[0].substr(0, 40) + "'");
    }
  }
  if (!have_format) Fail(path, line_number, "end_header before a format line");
  if (!vertex_seen) Fail(path, line_number, "no element vertex");
  int ix = -1, iy = -1, iz = -1, ii = -1;
  for (int k = 0; k < static_cast<int>(properties.size()); ++k) {
    const std::string& n = properties[static_cast<std::size_t>(k)].name;
    if (n == "x") ix = k;
    if (n == "y") iy = k;
    if (n == "z") iz = k;
    if (n == "intensity" || n == "scalar_intensity" || n == "reflectivity") ii = k;
  }
  if (ix < 0 || iy < 0 || iz < 0) Fail(path, vertex_line, "element vertex: needs x, y and z");
  sensors::PointCloud cloud;
  cloud.sensor = std::filesystem::path(path).stem().string();
  stats.points_in_file = static_cast<std::size_t>(count);
  std::vector<double> v(properties.size());
  auto add = [&]() {
    const double x = v[static_cast<std::size_t>(ix)], y = v[static_cast<std::size_t>(iy)],
                 z = v[static_cast<std::size_t>(iz)];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      ++stats.non_finite;
      return;
    }
    sensors::LidarPoint q;
    q.p_sensor =
        Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    if (ii >= 0 && std::isfinite(v[static_cast<std::size_t>(ii)])) {
      q.intensity = static_cast<float>(v[static_cast<std::size_t>(ii)]);
    }
    cloud.points.push_back(q);
  };
  if (format == Format::kAscii) {
    for (long long k = 0; k < count; ++k) {
      if (!std::getline(in, line)) {
        Fail(path, line_number + 1,
             "truncated: the header promises " + std::to_string(count) + " vertices, " +
                 std::to_string(k) + " follow");
      }
      ++line_number;
      std::istringstream words(line);
      std::size_t n = 0;
      for (std::string word; words >> word;) {
        if (n >= v.size()) break;
        char* end = nullptr;
        v[n] = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0') {
          Fail(path, line_number, "'" + word.substr(0, 40) + "' is not a number");
        }
        ++n;
      }
      if (n != v.size()) {
        Fail(path, line_number,
             "expected " + std::to_string(v.size()) + " values, got " + std::to_string(n));
      }
      add();
    }
    return cloud;
  }
  std::size_t row = 0;
  for (const Property& p : properties) row += static_cast<std::size_t>(p.size);
  const std::streamoff data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff available = in.tellg() - data_start;
  in.seekg(data_start);
  const auto needed = static_cast<long double>(row) * static_cast<long double>(count);
  if (needed > static_cast<long double>(available)) {
    Fail(path, 0,
         "binary data: the header promises " + std::to_string(count) + " vertices (" +
             std::to_string(static_cast<long long>(needed)) + " bytes), " +
             std::to_string(static_cast<long long>(available)) + " follow");
  }
  const bool swap = (format == Format::kBig) == (std::endian::native == std::endian::little);
  std::vector<unsigned char> buffer(row);
  for (long long k = 0; k < count; ++k) {
    in.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(row));
    std::size_t offset = 0;
    for (std::size_t n = 0; n < properties.size(); ++n) {
      v[n] = Decode(buffer.data() + offset, properties[n], swap);
      offset += static_cast<std::size_t>(properties[n].size);
    }
    add();
  }
  return cloud;
}

void WritePly(const std::string& path, const sensors::PointCloud& cloud) {
  std::ostringstream out;
  out << "ply\nformat binary_little_endian 1.0\ncomment autoshovel\nelement vertex "
      << cloud.points.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\n"
         "end_header\n";
  std::string bytes = out.str();
  for (const auto& p : cloud.points) {
    float f[4] = {p.p_sensor.x(), p.p_sensor.y(), p.p_sensor.z(), p.intensity};
    if constexpr (std::endian::native == std::endian::big) {
      for (float& x : f) {
        auto* b = reinterpret_cast<unsigned char*>(&x);
        std::reverse(b, b + 4);
      }
    }
    bytes.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  core::WriteFileAtomically(path, bytes);
}

}  // namespace autoshovel::identification

// The PCL translation unit of point cloud input and output (pcl::io).
#include "identification/camera_lidar/point_cloud_io.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "identification/camera_lidar/ply_io.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/input_file.h"

namespace autoshovel::identification {

namespace {

constexpr float kMaxRange = 10000.0f;  // [m], far beyond any LiDAR's range

[[noreturn]] void Fail(const std::string& file, int line, const std::string& key,
                       const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, line, line > 0 ? 1 : 0}, key, message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

std::vector<std::string> Split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

bool ParseLong(const std::string& word, long& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtol(word.c_str(), &end, 10);
  return errno == 0 && end != word.c_str() && *end == '\0';
}

bool ParseDouble(const std::string& word, double& value) {
  char* end = nullptr;
  value = std::strtod(word.c_str(), &end);
  return end != word.c_str() && *end == '\0';
}

void Reduce(std::vector<sensors::LidarPoint>& points, std::size_t max_points) {
  if (max_points == 0 || points.size() <= max_points) return;
  std::mt19937_64 rng(0x5eed);
  for (std::size_t i = 0; i < max_points; ++i) {  // partial Fisher–Yates, then keep order
    std::uniform_int_distribution<std::size_t> pick(i, points.size() - 1);
    std::swap(points[i], points[pick(rng)]);
  }
  points.resize(max_points);
}

// Checks the PCD header line by line (pcl::io reports problems on the console only) and the
// size of the data that follows.
void CheckPcd(const std::string& path, bool& has_intensity) {
  // Checked before opening: a named pipe would block the open, a folder would read as empty.
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Fail(path, 0, "", "cannot open the point cloud: " + why);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, 0, "", "cannot open the point cloud");
  std::vector<std::string> fields;
  std::vector<long> sizes, counts;
  std::vector<std::string> types;
  long width = -1, height = -1, points = -1;
  std::string data;
  int line_no = 0, fields_line = 0, data_line = 0, width_line = 0, points_line = 0;
  std::string line;
  const char* const keys[] = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                              "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  int next_key = 0;
  while (data.empty() && std::getline(in, line)) {
    ++line_no;
    // pcl::io skips empty lines but ends the header at one of only blanks (" ", a lone "\r"),
    // then decodes without fields: a null dereference (found by tests/fuzz). It splits on space,
    // tab and CR only, so a vertical tab or form feed would split the line differently there.
    if (!line.empty() && line.find_first_not_of(" \t\r\v\f") == std::string::npos) {
      Fail(path, line_no, "", "a header line of only blanks (pcl::io would end the header here)");
    }
    if (line.find_first_of("\v\f") != std::string::npos) {
      Fail(path, line_no, "", "a vertical tab or form feed in the header");
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> w = Split(line);
    if (w.empty()) continue;
    const std::string& key = w[0];
    int index = -1;
    for (int k = 0; k < 10; ++k) {
      if (key == keys[k]) index = k;
    }
    if (index < 0) Fail(path, line_no, "", "unknown PCD header entry '" + key + "'");
    if (index < next_key) {
      Fail(path, line_no, key,
           "out of order (PCD v0.7 order: VERSION FIELDS SIZE TYPE COUNT "
           "WIDTH HEIGHT VIEWPOINT POINTS DATA)");
    }
    next_key = index + 1;
    const std::size_t n = w.size() - 1;
    auto check_count = [&](std::size_t expected) {
      if (n != expected) {
        std::string names;
        for (const auto& f : fields) names += (names.empty() ? "" : " ") + f;
        Fail(path, line_no, key,
             "has " + std::to_string(n) + " values for " + std::to_string(expected) + " FIELDS (" +
                 names + ")");
      }
    };
    auto positive = [&](long& value, bool allow_zero) {
      if (n != 1 || !ParseLong(w[1], value) || value < (allow_zero ? 0 : 1)) {
        Fail(path, line_no, key,
             std::string("expected one integer ") + (allow_zero ? ">= 0" : "> 0") + ", got '" +
                 (n ? line.substr(line.find(w[1])) : "") + "'");
      }
    };
    if (key == "FIELDS") {
      fields.assign(w.begin() + 1, w.end());
      fields_line = line_no;
      if (fields.empty()) Fail(path, line_no, key, "no field names");
    } else if (key == "SIZE" || key == "COUNT") {
      check_count(fields.size());
      auto& out = key == "SIZE" ? sizes : counts;
      for (std::size_t i = 1; i <= n; ++i) {
        long v = 0;
        if (!ParseLong(w[i], v) || v < 1 || (key == "SIZE" && v != 1 && v != 2 && v != 4 && v != 8))
          Fail(path, line_no, key,
               "value " + std::to_string(i) + " '" + w[i] + "' is not " +
                   (key == "SIZE" ? "1, 2, 4 or 8" : "> 0"));
        out.push_back(v);
      }
    } else if (key == "TYPE") {
      check_count(fields.size());
      for (std::size_t i = 1; i <= n; ++i) {
        if (w[i] != "F" && w[i] != "I" && w[i] != "U")
          Fail(path, line_no, key,
               "value " + std::to_string(i) + " '" + w[i] + "' is not F, I or U");
      }
      types.assign(w.begin() + 1, w.end());
    } else if (key == "WIDTH") {
      positive(width, true);
      width_line = line_no;
    } else if (key == "HEIGHT") {
      positive(height, false);
    } else if (key == "POINTS") {
      positive(points, true);
      points_line = line_no;
    } else if (key == "VIEWPOINT") {
      if (n != 7)
        Fail(path, line_no, key,
             "expected 7 numbers (tx ty tz qw qx qy qz), got " + std::to_string(n));
      for (std::size_t i = 1; i <= n; ++i) {
        double v = 0;
        if (!ParseDouble(w[i], v) || !std::isfinite(v))
          Fail(path, line_no, key,
               "value " + std::to_string(i) + " '" + w[i] + "' is not a finite number");
      }
    } else if (key == "DATA") {
      if (n != 1 || (w[1] != "ascii" && w[1] != "binary" && w[1] != "binary_compressed"))
        Fail(path, line_no, key, "expected ascii, binary or binary_compressed");
      data = w[1];
      data_line = line_no;
    }
  }
  if (data.empty()) Fail(path, line_no, "", "truncated header: no DATA line");
  if (fields.empty()) Fail(path, data_line, "FIELDS", "missing");
  if (sizes.empty() || types.empty())
    Fail(path, data_line, sizes.empty() ? "SIZE" : "TYPE", "missing");
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (width < 0) Fail(path, data_line, "WIDTH", "missing");
  if (height < 0) height = 1;
  // Before any arithmetic on them and before pcl::io allocates: a 200-byte header may promise a
  // billion points, which pcl::io would try to hold.
  const long max_points = static_cast<long>(kMaxCloudPoints);
  const std::string limit = std::to_string(kMaxCloudPoints);
  if (points > max_points) {
    Fail(path, points_line, "POINTS",
         std::to_string(points) + " points, more than the " + limit +
             " a point cloud may have: not decoded");
  }
  if (width > max_points || width > max_points / height) {
    Fail(path, width_line, "WIDTH",
         std::to_string(width) + " x HEIGHT " + std::to_string(height) + " is more than the " +
             limit + " points a point cloud may have: not decoded");
  }
  if (points < 0) points = width * height;
  if (points != width * height) {
    Fail(path, data_line, "POINTS",
         std::to_string(points) + " != WIDTH x HEIGHT = " + std::to_string(width * height));
  }
  bool x = false, y = false, z = false;
  has_intensity = false;
  long values = 0, point_bytes = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    x = x || fields[i] == "x";
    y = y || fields[i] == "y";
    z = z || fields[i] == "z";
    has_intensity = has_intensity || fields[i] == "intensity";
    values += counts[i];
    point_bytes += counts[i] * sizes[i];
  }
  if (!x || !y || !z) Fail(path, fields_line, "FIELDS", "needs x, y and z");
  std::string names;
  for (const auto& f : fields) names += (names.empty() ? "" : " ") + f;
  if (data == "ascii") {
    long seen = 0;
    while (std::getline(in, line)) {
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const std::vector<std::string> w = Split(line);
      if (w.empty()) continue;
      if (seen == points)
        Fail(path, line_no, "", "more points than POINTS " + std::to_string(points));
      if (static_cast<long>(w.size()) != values) {
        Fail(path, line_no, "",
             "expected " + std::to_string(values) + " values (" + names + "), got " +
                 std::to_string(w.size()));
      }
      for (std::size_t i = 0; i < w.size(); ++i) {
        double v = 0;
        if (!ParseDouble(w[i], v) && w[i] != "nan" && w[i] != "NaN")
          Fail(path, line_no, "",
               "value " + std::to_string(i + 1) + " '" + w[i] + "' is not a number");
      }
      ++seen;
    }
    if (seen < points) {
      Fail(path, line_no + 1, "",
           "truncated: the header promises " + std::to_string(points) + " points, " +
               std::to_string(seen) + " follow");
    }
    return;
  }
  // pcl::io's header parser does not stop at DATA: it reads on, skipping empty lines, comments
  // and VERSION, and takes a line that starts with a header keyword for more header. Binary data
  // that begins like that redefines the fields under the decoder, which then reads out of
  // bounds (found by tests/fuzz: data starting with "COLUMNS", PCL's old name for FIELDS).
  const std::streamoff start = in.tellg();
  for (int at = line_no + 1; std::getline(in, line); ++at) {
    const std::vector<std::string> w = Split(line);
    if (line.empty() || (!w.empty() && (w[0][0] == '#' || w[0].starts_with("VERSION")))) continue;
    for (const char* header_key : {"FIELDS", "COLUMNS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT",
                                   "VIEWPOINT", "POINTS", "DATA"}) {
      if (!w.empty() && w[0].starts_with(header_key)) {
        Fail(path, at, "DATA",
             "the " + data + " data begins with '" + header_key +
                 "', which pcl::io would read as another header line");
      }
    }
    break;
  }
  in.clear();
  in.seekg(start);
  in.seekg(0, std::ios::end);
  const long remaining = static_cast<long>(in.tellg() - start);
  if (data == "binary") {
    if (remaining < points * point_bytes) {
      Fail(path, data_line, "DATA",
           "truncated: the header promises " + std::to_string(points) + " points (" +
               std::to_string(points * point_bytes) + " bytes), " + std::to_string(remaining) +
               " follow");
    }
    return;
  }
  std::uint32_t sizes_lzf[2] = {0, 0};
  in.seekg(start);
  if (remaining < 8 || !in.read(reinterpret_cast<char*>(sizes_lzf), 8)) {
    Fail(path, data_line, "DATA", "truncated: no compressed block sizes after the header");
  }
  if (sizes_lzf[1] != static_cast<std::uint32_t>(points * point_bytes)) {
    Fail(path, data_line, "DATA",
         "the compressed block unpacks to " + std::to_string(sizes_lzf[1]) +
             " bytes, the header promises " + std::to_string(points) + " points (" +
             std::to_string(points * point_bytes) + " bytes)");
  }
  if (remaining - 8 < static_cast<long>(sizes_lzf[0])) {
    Fail(path, data_line, "DATA",
         "truncated: the compressed block has " + std::to_string(sizes_lzf[0]) + " bytes, " +
             std::to_string(remaining - 8) + " follow");
  }
}

// One value of a field of the blob's point `i` as a double (any PCD type).
double FieldValue(const pcl::PCLPointCloud2& blob, const pcl::PCLPointField& field, std::size_t i) {
  const std::uint8_t* p = blob.data.data() + i * blob.point_step + field.offset;
  auto as = [p]<typename T>(T) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  };
  switch (field.datatype) {
    case pcl::PCLPointField::INT8:
      return as(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return as(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return as(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return as(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return as(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return as(std::uint32_t{});
    case pcl::PCLPointField::FLOAT32:
      return as(float{});
    case pcl::PCLPointField::FLOAT64:
      return as(double{});
    default:
      return 0.0;
  }
}

// The optional per-point `ring` (laser index) and `time_offset` (firing time after the frame's
// stamp, seconds) that recordings carry (runtime/recording): copied onto the points kept, which
// are the file's points in order less those with a non-finite coordinate.
void ReadRingAndTime(const pcl::PCLPointCloud2& blob, std::vector<sensors::LidarPoint>& points) {
  const pcl::PCLPointField* ring = nullptr;
  const pcl::PCLPointField* time = nullptr;
  const pcl::PCLPointField *x = nullptr, *y = nullptr, *z = nullptr;
  for (const pcl::PCLPointField& f : blob.fields) {
    if (f.name == "ring") ring = &f;
    if (f.name == "time_offset") time = &f;
    if (f.name == "x") x = &f;
    if (f.name == "y") y = &f;
    if (f.name == "z") z = &f;
  }
  if ((ring == nullptr && time == nullptr) || x == nullptr || y == nullptr || z == nullptr) return;
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  if (blob.data.size() < n * blob.point_step) return;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n && kept < points.size(); ++i) {
    if (!std::isfinite(FieldValue(blob, *x, i)) || !std::isfinite(FieldValue(blob, *y, i)) ||
        !std::isfinite(FieldValue(blob, *z, i))) {
      continue;
    }
    if (ring != nullptr) {
      const double r = FieldValue(blob, *ring, i);
      points[kept].ring = r >= 0 && r <= 65535 ? static_cast<std::uint16_t>(r) : 0;
    }
    if (time != nullptr) {
      const double t = FieldValue(blob, *time, i);
      points[kept].time_offset = std::isfinite(t) ? static_cast<float>(t) : 0.0f;
    }
    ++kept;
  }
}

sensors::PointCloud ReadPcd(const std::string& path, std::size_t max_points,
                            PointCloudReadStats& stats) {
  bool has_intensity = false;
  CheckPcd(path, has_intensity);
  pcl::PCLPointCloud2 blob;
  pcl::PCDReader reader;
  if (reader.read(path, blob) < 0) Fail(path, 0, "", "pcl::io could not decode the data");
  sensors::PointCloud cloud;
  cloud.sensor = std::filesystem::path(path).stem().string();
  if (has_intensity) {
    pcl::PointCloud<pcl::PointXYZI> points;
    pcl::fromPCLPointCloud2(blob, points);
    cloud.points.reserve(points.size());
    stats.points_in_file = points.size();
    for (const auto& p : points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ++stats.non_finite;
        continue;
      }
      sensors::LidarPoint q;
      q.p_sensor = Eigen::Vector3f(p.x, p.y, p.z);
      q.intensity = std::isfinite(p.intensity) ? p.intensity : 0.0f;
      cloud.points.push_back(q);
    }
  } else {
    pcl::PointCloud<pcl::PointXYZ> points;
    pcl::fromPCLPointCloud2(blob, points);
    stats.points_in_file = points.size();
    for (const auto& p : points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ++stats.non_finite;
        continue;
      }
      sensors::LidarPoint q;
      q.p_sensor = Eigen::Vector3f(p.x, p.y, p.z);
      cloud.points.push_back(q);
    }
  }
  ReadRingAndTime(blob, cloud.points);
  Reduce(cloud.points, max_points);
  return cloud;
}

sensors::PointCloud ReadKittiBin(const std::string& path, std::size_t max_points,
                                 PointCloudReadStats& stats) {
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Fail(path, 0, "", "cannot open the point cloud: " + why);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, 0, "", "cannot open the point cloud");
  in.seekg(0, std::ios::end);
  const long bytes = static_cast<long>(in.tellg());
  in.seekg(0);
  if (bytes % 16 != 0) {
    Fail(path, 0, "",
         "size " + std::to_string(bytes) +
             " bytes is not a multiple of 16 (float32 x, y, z, intensity per point)");
  }
  if (bytes / 16 > static_cast<long>(kMaxCloudPoints)) {
    Fail(path, 0, "",
         "size " + std::to_string(bytes) + " bytes is " + std::to_string(bytes / 16) +
             " points, more than the " + std::to_string(kMaxCloudPoints) +
             " a point cloud may have: not read");
  }
  stats.points_in_file = static_cast<std::size_t>(bytes / 16);
  sensors::PointCloud cloud;
  cloud.sensor = std::filesystem::path(path).stem().string();
  std::mt19937_64 rng(0x5eed);
  long seen = 0, offset = 0;
  float v[4];
  for (; in.read(reinterpret_cast<char*>(v), sizeof v); offset += sizeof v) {
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      ++stats.non_finite;
      continue;
    }
    // No LiDAR sees 10 km: such a coordinate is a file that is not float32 x y z i (text, a PCD
    // renamed .bin, float64), which would otherwise decode to a cloud of nonsense.
    for (int k = 0; k < 3; ++k) {
      if (std::abs(v[k]) > kMaxRange) {
        std::ostringstream message;
        message << "byte " << offset + 4 * k << " (point " << offset / 16 << ", "
                << "xyz"[k] << "): " << v[k] << " m is no LiDAR return (|"
                << "xyz"[k] << "| > " << kMaxRange << " m): not float32 x, y, z, intensity?";
        Fail(path, 0, "", message.str());
      }
    }
    sensors::LidarPoint q;
    q.p_sensor = Eigen::Vector3f(v[0], v[1], v[2]);
    q.intensity = std::isfinite(v[3]) ? v[3] : 0.0f;
    ++seen;
    if (max_points == 0 || cloud.points.size() < max_points) {
      cloud.points.push_back(q);
    } else {  // reservoir sampling (Vitter's algorithm R): memory stays at max_points
      std::uniform_int_distribution<long> pick(0, seen - 1);
      const long j = pick(rng);
      if (j < static_cast<long>(max_points)) cloud.points[j] = q;
    }
  }
  return cloud;
}

}  // namespace

sensors::PointCloud ReadPointCloud(const std::string& path, std::size_t max_points,
                                   PointCloudReadStats* stats) {
  PointCloudReadStats local;
  PointCloudReadStats& out = stats != nullptr ? *stats : local;
  out = {};
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".pcd") return ReadPcd(path, max_points, out);
  if (ext == ".bin") return ReadKittiBin(path, max_points, out);
  if (ext == ".ply") {
    sensors::PointCloud cloud = ReadPly(path, out);
    Reduce(cloud.points, max_points);
    return cloud;
  }
  Fail(path, 0, "", "unknown point cloud format '" + ext + "' (expected .pcd, .ply or .bin)");
}

void WritePcd(const std::string& path, const sensors::PointCloud& cloud, PcdEncoding encoding) {
  pcl::PointCloud<pcl::PointXYZI> points;
  points.reserve(cloud.points.size());
  for (const auto& p : cloud.points) {
    pcl::PointXYZI q;
    q.x = p.p_sensor.x();
    q.y = p.p_sensor.y();
    q.z = p.p_sensor.z();
    q.intensity = p.intensity;
    points.push_back(q);
  }
  points.width = static_cast<std::uint32_t>(points.size());
  points.height = 1;
  // PCL writes to a path only, unchecked against a full disk: it writes a scratch file beside the
  // target, whose bytes then go through the project's checked atomic write (core/file_output.h).
  std::string bytes;
  if (points.empty()) {  // PCL refuses to write an empty cloud; write the header by hand
    bytes =
        "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        "WIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA ascii\n";
  } else {
    const std::string scratch = path + ".pcl.tmp";
    pcl::PCDWriter writer;
    int rc = 0;
    if (encoding == PcdEncoding::kAscii) {
      rc = writer.writeASCII(scratch, points, 7);
    } else if (encoding == PcdEncoding::kBinary) {
      rc = writer.writeBinary(scratch, points);
    } else {
      rc = writer.writeBinaryCompressed(scratch, points);
    }
    std::ifstream in(scratch, std::ios::binary);
    std::ostringstream read_back;
    read_back << in.rdbuf();
    in.close();
    std::error_code ignored;
    std::filesystem::remove(scratch, ignored);
    if (rc != 0 || read_back.str().empty()) {
      throw core::OutputError(path, "pcl::io could not write the cloud");
    }
    bytes = read_back.str();
  }
  core::WriteFileAtomically(path, bytes);
}

void WriteKittiBin(const std::string& path, const sensors::PointCloud& cloud) {
  std::string bytes;
  bytes.reserve(cloud.points.size() * 16);
  for (const auto& p : cloud.points) {
    const float v[4] = {p.p_sensor.x(), p.p_sensor.y(), p.p_sensor.z(), p.intensity};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  core::WriteFileAtomically(path, bytes);
}

}  // namespace autoshovel::identification

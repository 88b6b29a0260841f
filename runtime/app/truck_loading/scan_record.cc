#include "runtime/app/truck_loading/scan_record.h"

#include <cstdint>
#include <cstdio>
#include <cstring>

#include "runtime/core/strings.h"

namespace autoshovel::app {
namespace {

std::string Num(double v) { return core::FormatNumber(v); }

// FNV-1a, 64 bits: a digest that any byte of the map changes, cheap and without a dependency.
class Fnv1a {
 public:
  void Add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ bytes[i]) * 0x100000001b3ull;
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

}  // namespace

recording::RecordedScan ToRecordedScan(const TruckScan& scan, recording::ScanKind kind, int pass) {
  recording::RecordedScan r;
  r.kind = kind;
  r.pass = pass;
  r.pulses_fired = scan.pulses_fired;
  r.points = scan.points;
  r.dust_evidence = scan.dust_evidence;
  r.max_azimuth_step = scan.max_azimuth_step;
  r.dust_warning = scan.dust_warning;
  r.min_speed_scale = scan.min_speed_scale;
  r.scanlines = scan.scanlines;
  r.scanline_azimuths = scan.scanline_azimuths;
  return r;
}

TruckScan FromRecordedScan(const recording::RecordedScan& scan) {
  TruckScan t;
  t.scanlines = scan.scanlines;
  t.scanline_azimuths = scan.scanline_azimuths;
  t.pulses_fired = scan.pulses_fired;
  t.points = scan.points;
  t.dust_evidence = scan.dust_evidence;
  t.max_azimuth_step = scan.max_azimuth_step;
  t.dust_warning = scan.dust_warning;
  t.min_speed_scale = scan.min_speed_scale;
  return t;
}

int FuseBedScan(planning::BedHeightMap& bed, const planning::BedHeightMap& seen) {
  int known = 0;
  for (int ix = 0; ix < seen.cells_x() && ix < bed.cells_x(); ++ix) {
    for (int iy = 0; iy < seen.cells_y() && iy < bed.cells_y(); ++iy) {
      if (!seen.known(ix, iy)) continue;
      bed.SetHeight(ix, iy, seen.height(ix, iy));
      ++known;
    }
  }
  return known;
}

std::string TruckReferenceRow(const perception::TruckRecognitionResult& truck, bool below_machine) {
  const Eigen::Vector3d t = truck.T_world_bed.translation();
  const perception::TruckBedDimensions& d = truck.dimensions;
  return std::string(truck.found ? "1" : "0") + "," + (below_machine ? "1" : "0") + "," +
         Num(t.x()) + "," + Num(t.y()) + "," + Num(t.z()) + "," + Num(truck.YawRad()) + "," +
         Num(d.length) + "," + Num(d.width) + "," + Num(d.wall_height) + "," + Num(d.floor_height) +
         "," + Num(d.rim_height) + "," + Num(truck.score) + "," +
         std::to_string(truck.support_points);
}

std::string BedMapReferenceRow(int scan, const planning::BedHeightMap& bed) {
  Fnv1a digest;
  double sum = 0;
  for (int ix = 0; ix < bed.cells_x(); ++ix) {
    for (int iy = 0; iy < bed.cells_y(); ++iy) {
      const unsigned char known = bed.known(ix, iy) ? 1 : 0;
      const double h = bed.height(ix, iy);
      digest.Add(&known, 1);
      digest.Add(&h, sizeof h);
      if (known) sum += h;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(digest.value()));
  const int known = bed.known_count();
  return std::to_string(scan) + "," + std::to_string(bed.cells_x()) + "," +
         std::to_string(bed.cells_y()) + "," + std::to_string(known) + "," +
         Num(known > 0 ? sum / known : 0.0) + "," + hex;
}

}  // namespace autoshovel::app

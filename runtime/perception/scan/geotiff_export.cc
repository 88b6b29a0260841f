#include "runtime/perception/scan/geotiff_export.h"

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <vector>

#include "runtime/core/file_output.h"

namespace autoshovel::perception {

void WriteGeoTiff(const std::string& path, const GridMap& map) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (driver == nullptr) throw core::OutputError(path, "GDAL has no GTiff driver");
  const int nx = map.size().x(), ny = map.size().y();
  // Written beside the target, then renamed over it, as every file of the project is
  // (core/file_output.h): a failed write leaves the previous file as it was.
  const std::string temporary = path + ".tmp";
  {
    char** creation = nullptr;
    creation = CSLSetNameValue(creation, "COMPRESS", "DEFLATE");
    std::unique_ptr<GDALDataset> data(
        driver->Create(temporary.c_str(), nx, ny, 3, GDT_Float32, creation));
    CSLDestroy(creation);
    if (!data) throw core::OutputError(path, CPLGetLastErrorMsg());
    // From here a throw deletes the dataset (unique_ptr) and must not leave the temporary.
    struct RemoveOnThrow {
      std::string file;
      bool armed = true;
      ~RemoveOnThrow() {
        if (armed) std::filesystem::remove(file);
      }
    } cleanup{temporary};
    // Row 0 of a GeoTIFF is the north (largest y) edge.
    const double r = map.resolution();
    const Eigen::Vector2d corner = map.position() - 0.5 * map.length();
    double transform[6] = {corner.x(), r, 0.0, corner.y() + ny * r, 0.0, -r};
    data->SetGeoTransform(transform);
    OGRSpatialReference local;
    local.SetLocalCS("autoshovel scan floor frame (metres)");
    data->SetSpatialRef(&local);
    const char* layers[3] = {"elevation", "variance", "filled"};
    std::vector<float> row(static_cast<std::size_t>(nx));
    for (int band = 0; band < 3; ++band) {
      GDALRasterBand* raster = data->GetRasterBand(band + 1);
      raster->SetNoDataValue(std::numeric_limits<double>::quiet_NaN());
      raster->SetDescription(band == 0 ? "height [m]" : band == 1 ? "sigma [m]" : "filled (Eq. 9)");
      const Eigen::MatrixXf& layer = map[layers[band]];
      for (int line = 0; line < ny; ++line) {
        const int y = ny - 1 - line;
        for (int x = 0; x < nx; ++x) {
          float v = layer(x, y);
          if (band == 1) v = std::isfinite(v) && v >= 0 ? std::sqrt(v) : NAN;
          if (band == 2) v = std::isfinite(map["elevation"](x, y)) ? (v > 0 ? 1.f : 0.f) : NAN;
          row[static_cast<std::size_t>(x)] = v;
        }
        if (raster->RasterIO(GF_Write, 0, line, nx, 1, row.data(), nx, 1, GDT_Float32, 0, 0) !=
            CE_None) {
          throw core::OutputError(path, CPLGetLastErrorMsg());
        }
      }
    }
    // GDALClose flushes the file (GDAL 3.6 has no GDALDataset::Close()); its failure shows in
    // the error state.
    CPLErrorReset();
    GDALClose(GDALDataset::ToHandle(data.release()));
    if (CPLGetLastErrorType() >= CE_Failure) throw core::OutputError(path, CPLGetLastErrorMsg());
    cleanup.armed = false;
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary);
    throw core::OutputError(path, ec.message());
  }
}

}  // namespace autoshovel::perception

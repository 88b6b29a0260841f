#include "identification/weights/demonstration_store.h"

#include <sqlite3.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "runtime/core/input_file.h"
#include "runtime/perception/semantic_map.h"

namespace autoshovel::identification {
namespace {

// The blobs are stored little-endian; this build writes its floats as they are in memory.
static_assert(std::endian::native == std::endian::little,
              "demonstration blobs are little-endian: add a byte swap for this platform");

constexpr std::uint8_t kUnknownClass = 255;

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct Finalize {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Db = std::unique_ptr<sqlite3, CloseDb>;
using Statement = std::unique_ptr<sqlite3_stmt, Finalize>;

[[noreturn]] void Fail(const std::filesystem::path& file, sqlite3* db, const std::string& what) {
  throw std::runtime_error(file.string() + ": " + what +
                           (db != nullptr ? std::string(": ") + sqlite3_errmsg(db) : ""));
}

Db Open(const std::filesystem::path& file, int flags) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(file.c_str(), &raw, flags, nullptr);
  Db db(raw);
  if (rc != SQLITE_OK) Fail(file, db.get(), "cannot open the demonstrations database");
  return db;
}

Statement Prepare(const std::filesystem::path& file, sqlite3* db, const char* sql) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &raw, nullptr) != SQLITE_OK) {
    Fail(file, db, std::string("not a demonstrations database (") + sql + ")");
  }
  return Statement(raw);
}

void Execute(const std::filesystem::path& file, sqlite3* db, const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error != nullptr ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error(file.string() + ": " + message);
  }
}

constexpr const char* kSchema = R"sql(
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE demonstrations (
  id INTEGER PRIMARY KEY, kind TEXT NOT NULL,
  resolution REAL NOT NULL, nx INTEGER NOT NULL, ny INTEGER NOT NULL,
  center_x REAL NOT NULL, center_y REAL NOT NULL,
  ground_a REAL NOT NULL, ground_b REAL NOT NULL, ground_c REAL NOT NULL,
  start_x REAL NOT NULL, start_y REAL NOT NULL, start_heading REAL NOT NULL,
  expert_x REAL NOT NULL, expert_y REAL NOT NULL, expert_heading REAL NOT NULL,
  elevation BLOB NOT NULL, class BLOB NOT NULL);
)sql";

}  // namespace

void WriteDemonstrations(const std::filesystem::path& file,
                         const std::vector<Demonstration>& demonstrations,
                         const std::map<std::string, std::string>& meta) {
  if (std::filesystem::exists(file)) {
    throw std::runtime_error(file.string() +
                             ": already exists; demonstrations are never overwritten (remove it "
                             "or choose another file)");
  }
  Db db = Open(file, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  Execute(file, db.get(), "BEGIN");
  Execute(file, db.get(), kSchema);
  Statement put_meta = Prepare(file, db.get(), "INSERT INTO meta VALUES (?, ?)");
  std::map<std::string, std::string> all = meta;
  all["format"] = kDemonstrationFormat;
  for (const auto& [key, value] : all) {
    sqlite3_bind_text(put_meta.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(put_meta.get(), 2, value.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(put_meta.get()) != SQLITE_DONE) Fail(file, db.get(), "cannot write meta");
    sqlite3_reset(put_meta.get());
  }
  Statement put = Prepare(file, db.get(),
                          "INSERT INTO demonstrations VALUES "
                          "(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  for (const Demonstration& d : demonstrations) {
    const perception::GridMap& m = d.map;
    const Eigen::MatrixXf& elevation = m["elevation"];
    const Eigen::MatrixXf& cls = m["class"];
    std::vector<std::uint8_t> classes(static_cast<std::size_t>(cls.size()));
    for (Eigen::Index i = 0; i < cls.size(); ++i) {
      const float c = cls.data()[i];
      classes[static_cast<std::size_t>(i)] =
          std::isnan(c) ? kUnknownClass : static_cast<std::uint8_t>(c);
    }
    sqlite3_stmt* s = put.get();
    int k = 1;
    sqlite3_bind_int64(s, k++, d.id);
    sqlite3_bind_text(s, k++, d.kind.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_double(s, k++, m.resolution());
    sqlite3_bind_int(s, k++, m.size().x());
    sqlite3_bind_int(s, k++, m.size().y());
    for (const double v : {m.position().x(), m.position().y(), d.ground_plane.x(),
                           d.ground_plane.y(), d.ground_plane.z(), d.start.xy.x(), d.start.xy.y(),
                           d.start.heading, d.expert_xy.x(), d.expert_xy.y(), d.expert_heading}) {
      sqlite3_bind_double(s, k++, v);
    }
    sqlite3_bind_blob(s, k++, elevation.data(), static_cast<int>(elevation.size() * sizeof(float)),
                      SQLITE_TRANSIENT);
    sqlite3_bind_blob(s, k++, classes.data(), static_cast<int>(classes.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(s) != SQLITE_DONE) {
      Fail(file, db.get(), "cannot write demonstration " + std::to_string(d.id));
    }
    sqlite3_reset(s);
  }
  Execute(file, db.get(), "COMMIT");
}

std::vector<Demonstration> ReadDemonstrations(const std::filesystem::path& file,
                                              std::map<std::string, std::string>* meta) {
  if (const std::string why = core::NotARegularFile(file); !why.empty()) {
    throw std::runtime_error(file.string() + ": cannot read the demonstrations: " + why);
  }
  Db db = Open(file, SQLITE_OPEN_READONLY);
  std::map<std::string, std::string> values;
  {
    Statement s = Prepare(file, db.get(), "SELECT key, value FROM meta");
    while (sqlite3_step(s.get()) == SQLITE_ROW) {
      const unsigned char* key = sqlite3_column_text(s.get(), 0);
      const unsigned char* value = sqlite3_column_text(s.get(), 1);
      if (key == nullptr || value == nullptr) {
        throw std::runtime_error(
            file.string() + ": meta: a NULL " +
            (key == nullptr
                 ? "key"
                 : "value of '" + std::string(reinterpret_cast<const char*>(key)) + "'"));
      }
      values[reinterpret_cast<const char*>(key)] = reinterpret_cast<const char*>(value);
    }
  }
  if (values["format"] != kDemonstrationFormat) {
    throw std::runtime_error(file.string() + ": format '" + values["format"] + "', expected '" +
                             kDemonstrationFormat + "'");
  }
  if (meta != nullptr) *meta = values;
  Statement s = Prepare(file, db.get(),
                        "SELECT id, kind, resolution, nx, ny, center_x, center_y, ground_a, "
                        "ground_b, ground_c, start_x, start_y, start_heading, expert_x, expert_y, "
                        "expert_heading, elevation, class FROM demonstrations ORDER BY id");
  std::vector<Demonstration> out;
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    sqlite3_stmt* r = s.get();
    Demonstration d;
    d.id = sqlite3_column_int(r, 0);
    const std::string where = file.string() + ": demonstration " + std::to_string(d.id) + ": ";
    const unsigned char* kind = sqlite3_column_text(r, 1);
    d.kind = kind != nullptr ? reinterpret_cast<const char*>(kind) : "";
    // A NULL or text where a number belongs would read as 0: refuse it, naming the column.
    for (int c = 2; c < 16; ++c) {
      const int type = sqlite3_column_type(r, c);
      if (type != SQLITE_FLOAT && type != SQLITE_INTEGER) {
        throw std::runtime_error(where + sqlite3_column_name(r, c) + " is " +
                                 (type == SQLITE_NULL ? std::string("NULL") : "not a number") +
                                 ", expected a number");
      }
    }
    const double resolution = sqlite3_column_double(r, 2);
    const int nx = sqlite3_column_int(r, 3), ny = sqlite3_column_int(r, 4);
    double v[11];
    for (int k = 0; k < 11; ++k) v[k] = sqlite3_column_double(r, 5 + k);
    for (int k = 0; k < 11; ++k) {
      if (!std::isfinite(v[k])) throw std::runtime_error(where + "a non-finite pose or plane");
    }
    if (!(resolution > 0) || nx <= 0 || ny <= 0 || nx > 10000 || ny > 10000) {
      throw std::runtime_error(where + "map of " + std::to_string(nx) + " x " + std::to_string(ny) +
                               " cells at " + std::to_string(resolution) +
                               " m: expected positive sizes");
    }
    const std::size_t cells = static_cast<std::size_t>(nx) * ny;
    if (static_cast<std::size_t>(sqlite3_column_bytes(r, 16)) != cells * sizeof(float) ||
        static_cast<std::size_t>(sqlite3_column_bytes(r, 17)) != cells) {
      throw std::runtime_error(where + "elevation or class blob is not " + std::to_string(nx) +
                               " x " + std::to_string(ny) + " cells");
    }
    d.map = perception::GridMap(resolution, Eigen::Vector2d(nx * resolution, ny * resolution),
                                Eigen::Vector2d(v[0], v[1]));
    d.map.Add("elevation");
    d.map.Add("class");
    Eigen::MatrixXf& elevation = d.map["elevation"];
    Eigen::MatrixXf& cls = d.map["class"];
    if (elevation.size() != static_cast<Eigen::Index>(cells)) {
      throw std::runtime_error(where + "the map's size does not match its cells");
    }
    std::memcpy(elevation.data(), sqlite3_column_blob(r, 16), cells * sizeof(float));
    for (std::size_t i = 0; i < cells; ++i) {  // NaN is "unknown"; an infinity is corrupt
      if (std::isinf(elevation.data()[i])) {
        throw std::runtime_error(where + "elevation at cell " + std::to_string(i) +
                                 " is infinite (NaN marks an unknown cell)");
      }
    }
    const auto* bytes = static_cast<const std::uint8_t*>(sqlite3_column_blob(r, 17));
    for (std::size_t i = 0; i < cells; ++i) {
      if (bytes[i] == kUnknownClass) {
        cls.data()[i] = std::numeric_limits<float>::quiet_NaN();
      } else if (bytes[i] <= static_cast<std::uint8_t>(perception::CellClass::kObstacle)) {
        cls.data()[i] = bytes[i];
      } else {
        throw std::runtime_error(where + "class byte " + std::to_string(bytes[i]) + " at cell " +
                                 std::to_string(i) +
                                 " (expected 0 ground, 1 pile, 2 obstacle, 255 unknown)");
      }
    }
    d.ground_plane = {v[2], v[3], v[4]};
    d.start = {{v[5], v[6]}, v[7]};
    d.expert_xy = {v[8], v[9]};
    d.expert_heading = v[10];
    out.push_back(std::move(d));
  }
  if (rc != SQLITE_DONE) Fail(file, db.get(), "cannot read the demonstrations");
  return out;
}

}  // namespace autoshovel::identification

#include "identification/camera_lidar/mask_io.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "identification/camera_lidar/image_header.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::identification {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void Fail(const std::string& file, int line, int column, const std::string& key,
                       const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, line, column}, key, message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

std::string SizeText(int w, int h) { return std::to_string(w) + " x " + std::to_string(h) + " px"; }

void CheckSize(const std::string& file, int mask_width, int mask_height, int width, int height) {
  if (mask_width != width || mask_height != height) {
    Fail(file, 0, 0, "",
         "mask is " + SizeText(mask_width, mask_height) + ", the image is " +
             SizeText(width, height));
  }
}

// Decodes a mask PNG only once its header says it is the image's size: cv::imread allocates
// what the header announces, however small the file (image_header.h).
cv::Mat ReadMaskPng(const std::string& file, int flags, int width, int height) {
  const ImageHeader header = ReadImageHeader(file);
  CheckSize(file, header.width, header.height, width, height);
  const cv::Mat m = cv::imread(file, flags);
  if (m.empty()) Fail(file, 0, 0, "", "cannot read the PNG");
  CheckSize(file, m.cols, m.rows, width, height);
  return m;
}

MaskSet ReadFolder(const std::string& dir, int width, int height) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".png")
      files.push_back(entry.path());
  }
  if (files.empty()) Fail(dir, 0, 0, "", "no mask PNGs in the folder");
  // SAM names them 0.png, 1.png, …: numeric order where the stems are numbers.
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    const std::string sa = a.stem().string(), sb = b.stem().string();
    const bool na = !sa.empty() && std::all_of(sa.begin(), sa.end(), ::isdigit);
    const bool nb = !sb.empty() && std::all_of(sb.begin(), sb.end(), ::isdigit);
    if (na && nb) return std::stol(sa) < std::stol(sb);
    return sa < sb;
  });
  MaskSet set{width, height, {}};
  for (const auto& f : files) {
    const cv::Mat m = ReadMaskPng(f.string(), cv::IMREAD_GRAYSCALE, width, height);
    set.masks.push_back(m > 127);
  }
  return set;
}

MaskSet ReadLabelPng(const std::string& path, int width, int height) {
  const cv::Mat raw = ReadMaskPng(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE, width, height);
  cv::Mat labels;
  raw.convertTo(labels, CV_32S);
  std::vector<int> values(labels.begin<int>(), labels.end<int>());
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  MaskSet set{width, height, {}};
  for (const int v : values) {
    if (v != 0) set.masks.push_back(labels == v);
  }
  if (set.masks.empty()) Fail(path, 0, 0, "", "label image has no non-zero label");
  return set;
}

MaskSet ReadCocoRle(const std::string& path, int width, int height) {
  // JSON is YAML 1.2 flow style: the project's YAML loader reads it with line marks, its size
  // limit and its duplicate-key check.
  core::DiagnosticSink sink;
  const YAML::Node root = core::LoadYamlFile(path, sink);
  sink.ThrowIfAny();
  YAML::Node records = root.IsMap() ? root["annotations"] : root;
  if (!records || !records.IsSequence()) {
    Fail(path, 1, 1, "", "expected a list of mask records or {\"annotations\": [...]}");
  }
  MaskSet set{width, height, {}};
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::string key = "[" + std::to_string(i) + "].segmentation";
    const YAML::Node seg = records[i]["segmentation"];
    const YAML::Mark mark = (seg ? seg : records[i]).Mark();
    const int line = mark.line + 1, column = mark.column + 1;
    if (!seg || !seg["size"] || !seg["counts"])
      Fail(path, line, column, key, "needs size and counts");
    int h = 0, w = 0;
    try {
      h = seg["size"][0].as<int>();
      w = seg["size"][1].as<int>();
    } catch (const YAML::Exception&) {
      Fail(path, line, column, key + ".size", "expected [height, width]");
    }
    if (w != width || h != height) {
      Fail(path, line, column, key + ".size",
           "mask is " + SizeText(w, h) + ", the image is " + SizeText(width, height));
    }
    std::vector<std::uint32_t> runs;
    try {
      if (seg["counts"].IsSequence()) {
        for (const auto& c : seg["counts"]) {
          const long v = c.as<long>();
          if (v < 0) throw std::invalid_argument("negative run length");
          runs.push_back(static_cast<std::uint32_t>(v));
        }
      } else {
        runs = DecodeRleString(seg["counts"].as<std::string>());
      }
      set.masks.push_back(DecodeRle(runs, h, w));
    } catch (const std::exception& e) {
      Fail(path, line, column, key + ".counts", e.what());
    }
  }
  if (set.masks.empty()) Fail(path, 1, 1, "", "no masks in the file");
  return set;
}

}  // namespace

MaskSet ReadMasks(const std::string& path, int width, int height) {
  if (fs::is_directory(path)) return ReadFolder(path, width, height);
  if (!fs::exists(path)) Fail(path, 0, 0, "", "no such mask file or folder");
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".json") return ReadCocoRle(path, width, height);
  if (ext == ".png") return ReadLabelPng(path, width, height);
  Fail(path, 0, 0, "", "unknown mask format (a folder of PNGs, a label .png or a COCO RLE .json)");
}

std::vector<std::uint32_t> DecodeRleString(const std::string& s) {
  // pycocotools maskApi.c rleFrString.
  std::vector<std::uint32_t> runs;
  std::size_t p = 0;
  while (p < s.size()) {
    long x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      if (p >= s.size()) throw std::invalid_argument("compressed RLE string ends inside a count");
      const int c = static_cast<int>(s[p]) - 48;
      if (c < 0 || c > 63) {
        throw std::invalid_argument("character '" + std::string(1, s[p]) + "' at " +
                                    std::to_string(p) + " is not compressed RLE");
      }
      x |= static_cast<long>(c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) x |= -1L << (5 * k);
    }
    if (runs.size() > 2) x += static_cast<long>(runs[runs.size() - 2]);
    if (x < 0) throw std::invalid_argument("negative run length in the compressed RLE");
    runs.push_back(static_cast<std::uint32_t>(x));
  }
  return runs;
}

cv::Mat DecodeRle(const std::vector<std::uint32_t>& runs, int height, int width) {
  const long total = static_cast<long>(height) * width;
  const long sum = std::accumulate(runs.begin(), runs.end(), 0L);
  if (sum != total) {
    throw std::invalid_argument("run lengths add up to " + std::to_string(sum) + ", not " +
                                std::to_string(height) + " x " + std::to_string(width) + " = " +
                                std::to_string(total));
  }
  cv::Mat mask(height, width, CV_8U, cv::Scalar(0));
  long index = 0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    if (r % 2 == 1) {
      for (long i = index; i < index + static_cast<long>(runs[r]); ++i) {
        mask.at<std::uint8_t>(static_cast<int>(i % height), static_cast<int>(i / height)) = 255;
      }
    }
    index += runs[r];
  }
  return mask;
}

std::string EncodeRleString(const cv::Mat& mask) {
  std::vector<long> runs;
  bool inside = false;
  long run = 0;
  for (int c = 0; c < mask.cols; ++c) {
    for (int r = 0; r < mask.rows; ++r) {
      const bool v = mask.at<std::uint8_t>(r, c) != 0;
      if (v != inside) {
        runs.push_back(run);
        run = 0;
        inside = v;
      }
      ++run;
    }
  }
  runs.push_back(run);
  std::string s;  // pycocotools rleToString
  for (std::size_t i = 0; i < runs.size(); ++i) {
    long x = runs[i];
    if (i > 2) x -= runs[i - 2];
    bool more = true;
    while (more) {
      long c = x & 0x1f;
      x >>= 5;
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      s += static_cast<char>(c + 48);
    }
  }
  return s;
}

void WriteMaskFolder(const std::string& dir, const MaskSet& masks) {
  core::CreateFolders(dir);
  for (std::size_t i = 0; i < masks.masks.size(); ++i) {
    const std::string file = dir + "/" + std::to_string(i) + ".png";
    plot::WriteImageFile(file, masks.masks[i]);
  }
}

MaskSet UndistortMasks(const MaskSet& masks, const CameraIntrinsics& intrinsics) {
  MaskSet out = masks;
  for (auto& m : out.masks) m = Undistort(m, intrinsics, true);
  return out;
}

cv::Mat MaskLabelImage(const MaskSet& masks) {
  cv::Mat labels(masks.height, masks.width, CV_32S, cv::Scalar(0));
  std::vector<std::size_t> order(masks.masks.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<int> area(masks.masks.size());
  for (std::size_t i = 0; i < area.size(); ++i) area[i] = cv::countNonZero(masks.masks[i]);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return area[a] > area[b]; });
  for (const std::size_t i : order) labels.setTo(static_cast<int>(i) + 1, masks.masks[i]);
  return labels;
}

MaskSet MasksFromLabels(const cv::Mat& labels, int min_area) {
  MaskSet set{labels.cols, labels.rows, {}};
  cv::Mat l32;
  labels.convertTo(l32, CV_32S);
  double lo = 0, hi = 0;
  cv::minMaxLoc(l32, &lo, &hi);
  for (int v = static_cast<int>(lo); v <= static_cast<int>(hi); ++v) {
    const cv::Mat binary = l32 == v;
    cv::Mat components;
    const int n = cv::connectedComponents(binary, components, 8, CV_32S);
    for (int c = 1; c < n; ++c) {
      cv::Mat m = components == c;
      if (cv::countNonZero(m) >= min_area) set.masks.push_back(m);
    }
  }
  return set;
}

MaskSet BuiltInSegmentation(const cv::Mat& bgr, int min_area) {
  cv::Mat blurred, lab, samples;
  cv::GaussianBlur(bgr, blurred, cv::Size(5, 5), 0);
  cv::cvtColor(blurred, lab, cv::COLOR_BGR2Lab);
  lab.reshape(1, lab.rows * lab.cols).convertTo(samples, CV_32F);
  cv::Mat cluster, centres;
  cv::setRNGSeed(1);
  cv::kmeans(samples, 6, cluster,
             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.5), 2,
             cv::KMEANS_PP_CENTERS, centres);
  cv::Mat labels = cluster.reshape(1, bgr.rows);
  cv::Mat l8;
  labels.convertTo(l8, CV_8U);
  cv::medianBlur(l8, l8, 5);  // removes speckle from the texture
  return MasksFromLabels(l8, min_area);
}

}  // namespace autoshovel::identification

// segmentation_eval: runs the segmentation network through perception::Segmenter over a held-out
// set and prints per-class IoU and mIoU, overall and per lighting, and the time per frame. The
// set is either rendered here from a seed (the default, never a training seed) or read from a
// folder written by segmentation_dataset.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "identification/segmentation/tool_args.h"
#include "identification/segmentation/yard_views.h"
#include "runtime/perception/segmentation.h"

namespace {

using namespace autoshovel;
namespace fs = std::filesystem;

constexpr const char* kUsage = R"(usage: segmentation_eval [options]

Segments a held-out set with the ONNX network and prints the IoU of every class, overall and per
lighting (IoU over all pixels of the set: TP / (TP + FP + FN)), the mean IoU over the classes
present, and the time per frame (network + softmax).

options:
  --model PATH       ONNX network (default: models/segmentation/yard_segmenter.onnx)
  --seed S           render the held-out set from seed S (default 1000; training used 1)
  --count N          views to render (default 300, a third per lighting)
  --first I          index of the first view (default 0)
  --scenarios A,B    scenario names (default: all)
  --data DIR         instead read DIR/split.csv and its PNG pairs (segmentation_dataset)
  --split NAME       with --data: only views of this split (default: all)
  --threads T        inference threads (default 1: the latency figure is for one core)
  --jobs J           rendering threads (default 2)
  --models DIR       models folder (default: the source tree's models/)
  --confusion 1      also print the confusion matrix of all views (rows: truth)
  --scale S          segment at S of the frame's resolution, probabilities brought back to
                     full size (default 1; perception::Segmenter::Run)
)";

struct Sample {
  std::string id;
  plant::Lighting lighting = plant::Lighting::kNormal;
  sensors::CameraFrame frame;
};

std::vector<Sample> Render(const identification::ToolArgs& args, std::string& what) {
  const identification::YardViewSampler sampler(
      args.String("models", AUTOSHOVEL_DEFAULT_MODELS_DIR), args.List("scenarios"));
  const std::int64_t seed = args.Int("seed", 1000), count = args.Int("count", 300);
  const std::int64_t first = args.Int("first", 0), jobs = args.Int("jobs", 2);
  if (count < 1 || seed < 0 || first < 0 || jobs < 1) {
    throw std::invalid_argument("--count, --jobs must be ≥ 1, --seed, --first ≥ 0");
  }
  what = std::to_string(count) + " views rendered from seed " + std::to_string(seed) + " (first " +
         std::to_string(first) + ")";
  std::vector<Sample> samples(static_cast<std::size_t>(count));
  identification::ParallelFor(count, jobs, [&](std::int64_t k) {
    identification::YardView v =
        sampler.Render(static_cast<std::uint64_t>(seed), static_cast<std::uint64_t>(first + k));
    Sample& s = samples[static_cast<std::size_t>(k)];
    s.id = std::to_string(first + k);
    s.lighting = v.lighting;
    s.frame = std::move(v.frame);
  });
  return samples;
}

std::vector<Sample> Read(const identification::ToolArgs& args, std::string& what) {
  const fs::path dir = args.String("data", "");
  const std::string only = args.String("split", "");
  std::ifstream csv(dir / "split.csv");
  if (!csv) throw std::runtime_error("cannot read " + (dir / "split.csv").string());
  std::vector<Sample> samples;
  for (std::string line; std::getline(csv, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("id,", 0) == 0) continue;
    std::vector<std::string> cols;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cols.push_back(c);
    if (cols.size() < 3) throw std::runtime_error("malformed line in split.csv: " + line);
    if (!only.empty() && cols[1] != only) continue;
    Sample s;
    s.id = cols[0];
    const auto lighting = plant::ParseLighting(cols[2]);
    if (!lighting) throw std::runtime_error("unknown lighting in split.csv: " + line);
    s.lighting = *lighting;
    const std::string image_path = (dir / "images" / (s.id + ".png")).string();
    const std::string label_path = (dir / "labels" / (s.id + ".png")).string();
    const cv::Mat image = cv::imread(image_path, cv::IMREAD_COLOR);
    const cv::Mat labels = cv::imread(label_path, cv::IMREAD_UNCHANGED);
    if (image.empty() || labels.empty() || labels.type() != CV_8UC1 ||
        labels.size() != image.size()) {
      throw std::runtime_error("cannot read the pair " + image_path + ", " + label_path);
    }
    s.frame.width = image.cols;
    s.frame.height = image.rows;
    s.frame.bgr.assign(image.datastart, image.dataend);
    s.frame.labels.assign(labels.datastart, labels.dataend);
    samples.push_back(std::move(s));
  }
  if (samples.empty()) throw std::runtime_error("no views in " + (dir / "split.csv").string());
  what = std::to_string(samples.size()) + " views from " + dir.string() +
         (only.empty() ? "" : " (split " + only + ")");
  return samples;
}

std::string Percent(const std::optional<double>& v) {
  if (!v) return "n/a";
  char buf[16];
  std::snprintf(buf, sizeof buf, "%.2f", 100.0 * *v);
  return buf;
}

int Run(int argc, char** argv) {
  const identification::ToolArgs args(argc, argv,
                                      {"model", "seed", "count", "first", "scenarios", "data",
                                       "split", "threads", "jobs", "models", "confusion", "scale"});
  if (args.help()) {
    std::cout << kUsage;
    return 0;
  }
  const std::string model_path = args.String(
      "model", std::string(AUTOSHOVEL_DEFAULT_MODELS_DIR) + "/segmentation/yard_segmenter.onnx");
  const std::int64_t threads = args.Int("threads", 1);
  if (threads < 1) throw std::invalid_argument("--threads must be ≥ 1");
  const double scale = std::stod(args.String("scale", "1"));
  if (!(scale > 0 && scale <= 1)) throw std::invalid_argument("--scale must be in (0, 1]");

  std::string what;
  const std::vector<Sample> samples = args.has("data") ? Read(args, what) : Render(args, what);

  perception::SetInferenceThreads(static_cast<int>(threads));
  const perception::Segmenter segmenter(model_path);
  // Index 0: all views; 1 + lighting: per lighting.
  std::vector<identification::ConfusionMatrix> matrices(4);
  std::vector<int> views(4, 0);
  std::vector<double> ms;
  for (const Sample& s : samples) {
    const auto t0 = std::chrono::steady_clock::now();
    const perception::SegmentationResult r = segmenter.Run(s.frame, scale);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    for (const int k : {0, 1 + static_cast<int>(s.lighting)}) {
      matrices[k].Add(s.frame.labels, r.labels);
      ++views[k];
    }
  }

  std::cout << "model " << model_path << " at scale " << scale << "\nheld-out set: " << what
            << "\n\n";
  std::cout << "| class | all | normal | bright | dim | share of pixels |\n"
               "| --- | --- | --- | --- | --- | --- |\n";
  const double total_pixels =
      static_cast<double>(samples.size()) * samples[0].frame.width * samples[0].frame.height;
  for (int c = 0; c < core::kNumSemanticClasses; ++c) {
    std::cout << "| " << core::kSemanticClassNames[c];
    for (int k = 0; k < 4; ++k) std::cout << " | " << Percent(matrices[k].Iou(c));
    char share[16];
    std::snprintf(share, sizeof share, "%.2f%%",
                  100.0 * static_cast<double>(matrices[0].TruthPixels(c)) / total_pixels);
    std::cout << " | " << share << " |\n";
  }
  std::cout << "| **mean IoU** ";
  for (int k = 0; k < 4; ++k) {
    std::cout << "| **" << (views[k] ? Percent(matrices[k].MeanIou()) : "n/a") << "** ";
  }
  std::cout << "| |\n| pixel accuracy ";
  for (int k = 0; k < 4; ++k) {
    std::cout << "| " << (views[k] ? Percent(matrices[k].PixelAccuracy()) : "n/a") << " ";
  }
  std::cout << "| |\n| views ";
  for (int k = 0; k < 4; ++k) std::cout << "| " << views[k] << " ";
  std::cout << "| |\n\n";

  if (args.Int("confusion", 0) != 0) {
    std::cout << "confusion, all views: per true class (row), the share of its pixels given each "
                 "label (column), %\n\n| truth \\ label |";
    for (const auto name : core::kSemanticClassNames) std::cout << ' ' << name << " |";
    std::cout << "\n|---|";
    for (int c = 0; c < core::kNumSemanticClasses; ++c) std::cout << "---|";
    std::cout << '\n';
    for (int t = 0; t < core::kNumSemanticClasses; ++t) {
      std::cout << "| " << core::kSemanticClassNames[t] << " |";
      const double n = static_cast<double>(std::max<std::uint64_t>(1, matrices[0].TruthPixels(t)));
      for (int p = 0; p < core::kNumSemanticClasses; ++p) {
        char cell[16];
        std::snprintf(cell, sizeof cell, " %.3f |",
                      100.0 * static_cast<double>(matrices[0].count(t, p)) / n);
        std::cout << cell;
      }
      std::cout << '\n';
    }
    std::cout << '\n';
  }

  // The first frames include one-off allocations: the median is the steady figure.
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  double mean = 0;
  for (const double t : ms) mean += t / static_cast<double>(ms.size());
  std::printf(
      "time per %dx%d frame, %lld inference thread(s): median %.1f ms, mean %.1f ms, "
      "95th percentile %.1f ms\n",
      samples[0].frame.width, samples[0].frame.height, static_cast<long long>(threads),
      sorted[sorted.size() / 2], mean,
      sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)]);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return identification::RunTool("segmentation_eval", Run, argc, argv);
}

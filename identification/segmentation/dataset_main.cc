// segmentation_dataset: renders random camera views of the simulated yards (yard_views.h) and
// writes them as PNG pairs (8-bit BGR image, 8-bit class-index label) plus a split file, the
// training and evaluation data of the segmentation network. Deterministic from --seed: view i
// depends on (seed, i) only, whatever --jobs.
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "identification/segmentation/tool_args.h"
#include "identification/segmentation/yard_views.h"
#include "runtime/core/file_output.h"
#include "runtime/plot/image_file.h"

namespace {

using namespace autoshovel;
namespace fs = std::filesystem;

constexpr const char* kUsage = R"(usage: segmentation_dataset --out DIR [options]

Renders random views of the yards in models/scenarios (normal, bright and dim light in turn) and
writes DIR/images/NNNNNN.png (BGR), DIR/labels/NNNNNN.png (class index per pixel, 0..6 in the
order of core::SemanticClass) and DIR/split.csv (one line per view: id, split, lighting,
scenario, machine, pose, joints, added piles and obstacles).

options:
  --out DIR          output folder (created)
  --count N          number of views (default 3000)
  --first I          index of the first view (default 0): sets can be made in pieces
  --seed S           seed of the set (default 1); a held-out set is another seed
  --val-every K      every K-th view goes to split "val", the others to "train" (default 10;
                     0: none)
  --split NAME       put every view into split NAME instead (e.g. test)
  --lighting L       normal | bright | dim for every view (default: view index mod 3)
  --scenarios A,B    scenario names (default: every scenario under MODELS/scenarios)
  --models DIR       models folder (default: the source tree's models/)
  --jobs J           rendering threads (default 2)
)";

std::string Fixed(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string CsvLine(const std::string& id, const std::string& split,
                    const identification::YardView& v) {
  std::ostringstream line;
  line << id << ',' << split << ',' << plant::ToString(v.lighting) << ',' << v.scenario << ','
       << v.machine << ',' << Fixed(v.x, 3) << ',' << Fixed(v.y, 3) << ',' << Fixed(v.heading, 4)
       << ',' << Fixed(v.articulation, 4) << ',';
  for (std::size_t j = 0; j < v.joints.size(); ++j) {
    line << (j ? ";" : "") << Fixed(v.joints[j], 4);
  }
  line << ',' << v.extra_piles << ',' << v.extra_obstacles;
  return line.str();
}

int Run(int argc, char** argv) {
  const identification::ToolArgs args(argc, argv,
                                      {"out", "count", "first", "seed", "val-every", "split",
                                       "lighting", "scenarios", "models", "jobs"});
  if (args.help() || !args.has("out")) {
    std::cout << kUsage;
    return args.help() ? 0 : 2;
  }
  const fs::path out = args.String("out", "");
  const std::int64_t count = args.Int("count", 3000);
  const std::int64_t first = args.Int("first", 0);
  const std::int64_t seed = args.Int("seed", 1);
  const std::int64_t val_every = args.Int("val-every", 10);
  const std::int64_t jobs = args.Int("jobs", 2);
  if (count < 1 || first < 0 || seed < 0 || val_every < 0 || jobs < 1) {
    throw std::invalid_argument("--count and --jobs must be ≥ 1, --first, --seed, --val-every ≥ 0");
  }
  std::optional<plant::Lighting> lighting;
  if (args.has("lighting")) {
    lighting = plant::ParseLighting(args.String("lighting", ""));
    if (!lighting) throw std::invalid_argument("--lighting: expected normal, bright or dim");
  }
  const identification::YardViewSampler sampler(
      args.String("models", AUTOSHOVEL_DEFAULT_MODELS_DIR), args.List("scenarios"));
  core::CreateFolders(out / "images");
  core::CreateFolders(out / "labels");

  std::vector<std::string> lines(static_cast<std::size_t>(count));
  std::atomic<std::int64_t> done{0};
  identification::ParallelFor(count, jobs, [&](std::int64_t k) {
    const std::int64_t index = first + k;
    const identification::YardView v = sampler.Render(static_cast<std::uint64_t>(seed),
                                                      static_cast<std::uint64_t>(index), lighting);
    char id[16];
    std::snprintf(id, sizeof id, "%06lld", static_cast<long long>(index));
    const cv::Mat bgr(v.frame.height, v.frame.width, CV_8UC3,
                      const_cast<std::uint8_t*>(v.frame.bgr.data()));
    const cv::Mat labels(v.frame.height, v.frame.width, CV_8UC1,
                         const_cast<std::uint8_t*>(v.frame.labels.data()));
    // Checked and atomic (runtime/plot/image_file.h): no half PNG in a training set.
    plot::WriteImageFile(out / "images" / (std::string(id) + ".png"), bgr);
    plot::WriteImageFile(out / "labels" / (std::string(id) + ".png"), labels);
    const std::string split = args.has("split") ? args.String("split", "")
                              : (val_every > 0 && index % val_every == val_every - 1) ? "val"
                                                                                      : "train";
    lines[static_cast<std::size_t>(k)] = CsvLine(id, split, v);
    const std::int64_t n = ++done;
    if (n % 100 == 0 || n == count) {
      std::fprintf(stderr, "\r%lld / %lld views", static_cast<long long>(n),
                   static_cast<long long>(count));
    }
  });
  std::fprintf(stderr, "\n");

  // Appends when the set is made in pieces (--first > 0), so one split file lists them all.
  const fs::path split_file = out / "split.csv";
  const bool fresh = first == 0 || !fs::exists(split_file);
  std::ostringstream csv;  // the old file's rows, then the new ones, in one checked write
  if (!fresh) {
    std::ifstream old(split_file, std::ios::binary);
    csv << old.rdbuf();
  }
  if (fresh) {
    csv << "# segmentation_dataset --seed " << seed << "; scenarios:";
    for (const std::string& s : sampler.scenario_names()) csv << ' ' << s;
    csv << "\nid,split,lighting,scenario,machine,x,y,heading,articulation,joints,extra_piles,"
           "extra_obstacles\n";
  }
  for (const std::string& line : lines) csv << line << '\n';
  core::WriteFileAtomically(split_file, csv.str());
  std::cout << "wrote " << count << " views to " << out.string() << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return identification::RunTool("segmentation_dataset", Run, argc, argv);
}

// Latency of the shipped segmentation network on a 480×383 camera frame (network, padding,
// softmax and argmax), on one inference thread (the figure the README reports) and on two.
//   build/segmentation_bench --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <string>

#include "identification/segmentation/yard_views.h"
#include "runtime/perception/segmentation.h"

namespace {

using namespace autoshovel;

std::string SourcePath(const std::string& relative) {
  return std::string(AUTOSHOVEL_SOURCE_DIR) + "/" + relative;
}

struct Setup {
  perception::Segmenter segmenter{SourcePath("models/segmentation/yard_segmenter.onnx")};
  sensors::CameraFrame frame =
      identification::YardViewSampler(SourcePath("models"), {"mixing_station"})
          .Render(7, 0, plant::Lighting::kNormal)
          .frame;
};

Setup& Shared() {
  static Setup s;
  return s;
}

void BM_SegmentFrame(benchmark::State& st) {
  Setup& s = Shared();
  perception::SetInferenceThreads(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    const perception::SegmentationResult r = s.segmenter.Run(s.frame);
    benchmark::DoNotOptimize(r.labels.data());
  }
  st.SetLabel(std::to_string(s.frame.width) + "x" + std::to_string(s.frame.height) + ", " +
              std::to_string(st.range(0)) + " thread(s)");
}
BENCHMARK(BM_SegmentFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

#include "identification/weights/demonstration_generation.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

#include "identification/weights/demo_scenes.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/sim/select_command.h"

namespace autoshovel::identification {
namespace {

// SplitMix64 finaliser: decorrelates the slot and attempt numbers from the run's seed.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

constexpr int kMaxAttemptsPerSlot = 20;

// One slot: scenes from the slot's seeds until the expert picks something.
Demonstration MakeOne(const model::MachineDescription& machine,
                      const planning::LoaderGeometry& loader,
                      const planning::ShovelPointConfig& config,
                      const DemonstrationGenerationOptions& options, int slot) {
  for (int attempt = 0; attempt < kMaxAttemptsPerSlot; ++attempt) {
    const std::uint64_t seed = Mix(Mix(options.seed) ^ Mix(static_cast<std::uint64_t>(slot) << 8 |
                                                           static_cast<std::uint64_t>(attempt)));
    const DemoScene scene = RandomDemoScene(machine, seed);
    Demonstration d;
    d.id = slot;
    d.kind = scene.kind;
    d.map = sim::TruthMap(scene.scenario, options.map_resolution);
    d.ground_plane = Eigen::Vector3d::Zero();  // the simulated floor is z = 0
    d.start = scene.start;
    perception::GridMap map = d.map;
    const std::vector<perception::ExtractedPile> piles =
        perception::ExtractPiles(map, d.ground_plane);
    const std::vector<planning::CandidatePose> candidates =
        planning::GenerateCandidates(map, piles, config);
    const int chosen = ChooseLikeAnExpert(scene.scenario.world, candidates, scene.start,
                                          loader.bucket_width, options.expert, Mix(seed));
    if (chosen < 0) continue;
    d.expert_xy = candidates[chosen].xy;
    d.expert_heading = candidates[chosen].entry_heading;
    return d;
  }
  throw std::runtime_error("demonstration " + std::to_string(slot) + ": no scene in " +
                           std::to_string(kMaxAttemptsPerSlot) +
                           " attempts had a candidate the expert would take");
}

}  // namespace

std::vector<Demonstration> GenerateDemonstrations(const model::MachineDescription& machine,
                                                  const planning::LoaderGeometry& loader,
                                                  const planning::ShovelPointConfig& config,
                                                  const DemonstrationGenerationOptions& options) {
  if (options.count < 1) throw std::invalid_argument("demonstrations: count must be >= 1");
  std::vector<Demonstration> out(static_cast<std::size_t>(options.count));
  const int threads = std::clamp(
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency()),
      1, options.count);
  std::atomic<int> next{0}, done{0};
  std::mutex error_mutex, progress_mutex;
  std::exception_ptr error;
  const auto work = [&] {
    for (int slot; (slot = next.fetch_add(1)) < options.count;) {
      try {
        out[static_cast<std::size_t>(slot)] = MakeOne(machine, loader, config, options, slot);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = options.count;  // stop handing out slots
      }
      const int finished = ++done;
      if (options.progress) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        options.progress(finished, options.count);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return out;
}

}  // namespace autoshovel::identification

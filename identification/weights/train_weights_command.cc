#include "identification/weights/train_weights_command.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "generated/registry.h"
#include "identification/weights/demonstration_generation.h"
#include "identification/weights/weight_tuning.h"
#include "runtime/core/file_output.h"
#include "runtime/core/progress_line.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {
namespace {

constexpr const char* kCommand = "autoshovel train weights";
constexpr const char* kWeightNames[5] = {"k_t", "k_s", "k_c", "k_e", "k_a"};

bool HeldOut(int id) { return id % 5 == 4; }

// done/total, rate, ETA: rewritten in place on a terminal, a line per update elsewhere
// (core/progress_line.h).
class Progress {
 public:
  Progress(std::ostream& out, std::string what) : line_(out), what_(std::move(what)) {}
  void Update(int done, int total) {
    const double elapsed = Seconds();
    const double interval = line_.terminal() ? 0.5 : 10.0;
    if (finished_ || (done < total && elapsed - last_ < interval)) return;
    finished_ = done >= total;
    last_ = elapsed;
    const double rate = elapsed > 0 ? done / elapsed : 0;
    const double eta = rate > 0 ? (total - done) / rate : 0;
    char line[160];
    std::snprintf(line, sizeof line, "%s %d/%d (%.1f/s, ETA %.0f s)", what_.c_str(), done, total,
                  rate, eta);
    if (done >= total) {
      line_.Finish(line);
    } else {
      line_.Update(line);
    }
  }
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  core::ProgressLine line_;
  std::string what_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double last_ = -1;
  bool finished_ = false;
};

std::vector<ScoredDemonstration> ScoreAll(const std::vector<Demonstration>& demonstrations,
                                          const planning::LoaderGeometry& loader, int threads,
                                          std::ostream& out) {
  std::vector<ScoredDemonstration> scored(demonstrations.size());
  Progress progress(out, "scoring candidates (Algorithm 2)");
  std::atomic<int> next{0}, done{0};
  std::mutex mutex;
  const int n = static_cast<int>(demonstrations.size());
  const auto work = [&] {
    for (int i; (i = next.fetch_add(1)) < n;) {
      scored[i] = ScoreDemonstration(demonstrations[i], loader, {});
      const int finished = ++done;
      const std::lock_guard<std::mutex> lock(mutex);
      progress.Update(finished, n);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return scored;
}

void PrintAgreement(std::ostream& out, const char* set, const char* weights, const Agreement& a) {
  char line[200];
  std::snprintf(line, sizeof line, "| %s | %s | %d | %.1f %% | %.1f %% | %.2f | %.2f | %.1f %% |\n",
                set, weights, a.demonstrations, 100 * a.within_1m, 100 * a.within_2m,
                a.mean_distance, a.median_distance, 100 * a.best_possible_within_1m);
  out << line;
}

void WriteWeights(const std::filesystem::path& file, const ShovelWeights& w,
                  const TrainWeightsOptions& o, int demonstrations, const Agreement& before,
                  const Agreement& after) {
  std::ostringstream f;  // then one checked atomic write (core/file_output.h)
  f << "# Eq. (18) weights tuned by `" << kCommand << "` (wheel-loader seed §5) on "
    << demonstrations << " demonstrations from " << o.demos << ", seed " << o.seed << ".\n";
  char line[200];
  std::snprintf(line, sizeof line,
                "# Held-out agreement within 1 m: %.1f %% with Table 1's weights, %.1f %% with "
                "these.\n",
                100 * before.within_1m, 100 * after.within_1m);
  f << line;
  for (int k = 0; k < 5; ++k) {
    std::snprintf(line, sizeof line, "%s: %.4f\n", kWeightNames[k], w[k]);
    f << line;
  }
  core::WriteFileAtomically(file, f.str());
}

}  // namespace

int RunTrainWeights(const TrainWeightsOptions& o, std::ostream& out, std::ostream& err) {
  try {
    if (std::filesystem::exists(o.out)) {
      err << kCommand << ": " << o.out
          << " already exists; weights are never overwritten (choose another --out)\n";
      return 2;
    }
    if (o.evaluations < 10) {
      err << kCommand << ": --evaluations must be at least 10, got " << o.evaluations << "\n";
      return 2;
    }
    const model::MachineDescription machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(o.machine, o.models_dir));
    if (machine.swing) {
      err << kCommand << ": '" << machine.name
          << "' is not a wheel loader; shovel points are for loaders\n";
      return 2;
    }
    const generated::MachineFunctions* functions = nullptr;
    try {
      functions = &machines::MachineFunctionsFor(machine);
    } catch (const machines::MachineCodeError& e) {
      err << kCommand << ": " << e.what() << "\n";
      return 2;
    }
    const planning::LoaderGeometry loader = planning::LoaderGeometryFrom(machine, *functions);
    const int threads = o.threads > 0
                            ? o.threads
                            : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

    std::vector<Demonstration> demonstrations;
    if (o.generate > 0) {
      if (std::filesystem::exists(o.demos)) {
        err << kCommand << ": " << o.demos
            << " already exists; --generate writes a new file (omit --generate to use it)\n";
        return 2;
      }
      DemonstrationGenerationOptions g;
      g.count = o.generate;
      g.seed = o.seed;
      g.threads = threads;
      Progress progress(out, "generating expert demonstrations");
      g.progress = [&](int done, int total) { progress.Update(done, total); };
      demonstrations = GenerateDemonstrations(machine, loader, {}, g);
      WriteDemonstrations(o.demos, demonstrations,
                          {{"generator", "autoshovel train weights --generate"},
                           {"seed", std::to_string(o.seed)},
                           {"machine", machine.name},
                           {"count", std::to_string(o.generate)}});
      out << "wrote " << demonstrations.size() << " demonstrations to " << o.demos << "\n";
    } else {
      demonstrations = ReadDemonstrations(o.demos);
      out << "read " << demonstrations.size() << " demonstrations from " << o.demos << "\n";
    }
    if (demonstrations.size() < 5) {
      err << kCommand << ": " << o.demos << " holds " << demonstrations.size()
          << " demonstrations; at least 5 are needed for an 80/20 split\n";
      return 2;
    }

    const std::vector<ScoredDemonstration> scored = ScoreAll(demonstrations, loader, threads, out);
    std::vector<ScoredDemonstration> training, held_out;
    for (const ScoredDemonstration& s : scored) (HeldOut(s.id) ? held_out : training).push_back(s);

    const ShovelWeights table1 = WeightsOf({});
    WeightTuningOptions t;
    t.max_evaluations = o.evaluations;
    t.seed = o.seed;
    Progress progress(out, "CMA-ES evaluations");
    t.progress = [&](int evaluations, double) {
      progress.Update(std::min(evaluations, o.evaluations), o.evaluations);
    };
    const WeightTuningResult r = TuneWeights(training, table1, t);
    progress.Update(o.evaluations, o.evaluations);

    out << "CMA-ES: " << r.evaluations << " evaluations, stopped by " << r.stop_reason
        << "; training mean distance " << r.objective << " m\n\n";
    out << "| set | weights | demonstrations | within 1 m | within 2 m | mean m | median m | "
           "best possible within 1 m |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n";
    const Agreement train_before = MeasureAgreement(training, table1);
    const Agreement train_after = MeasureAgreement(training, r.weights);
    const Agreement before = MeasureAgreement(held_out, table1);
    const Agreement after = MeasureAgreement(held_out, r.weights);
    PrintAgreement(out, "training", "Table 1", train_before);
    PrintAgreement(out, "training", "tuned", train_after);
    PrintAgreement(out, "held out", "Table 1", before);
    PrintAgreement(out, "held out", "tuned", after);
    out << "\n| weight | Table 1 | tuned |\n| --- | --- | --- |\n";
    for (int k = 0; k < 5; ++k) {
      char line[80];
      std::snprintf(line, sizeof line, "| %s | %.3f | %.3f |\n", kWeightNames[k], table1[k],
                    r.weights[k]);
      out << line;
    }
    WriteWeights(o.out, r.weights, o, static_cast<int>(demonstrations.size()), before, after);
    out << "\nweights: " << o.out << "\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::identification

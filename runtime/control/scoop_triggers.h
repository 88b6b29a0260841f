// When the crowding ends and the scoop begins, wheel-loader seed §6.1–6.2, §7.4.2 (Table 5):
//  - PredictedVolumeTrigger: V1 + V2 ≥ V_t (Algorithm 3 line 7), the proposed method, with
//    V1 + V2 scaled by the penetration model's intake factor κ_M where it has one
//    (penetration_predictor.h): κ_M·(V1 + V2) ≥ V_t;
//  - PerceptionTrigger: V1 ≥ V_t, "perception-triggered methods without shoveling volume
//    prediction" (Fig. 10(c));
//  - BoomPressureTrigger: the boom cylinder's cap pressure reaches a threshold, the "Pressure"
//    baseline of Table 5 (Cao et al. 2023). The threshold must hold for `hold_cycles` decisions
//    in a row so that one pressure spike (a stone) does not fire it.
// Every trigger sees the same inputs; a stalled machine (Algorithm 3 line 13) is handled by the
// scoop cycle for all of them, not here.
#pragma once

#include <memory>
#include <string>

namespace autoshovel::control {

struct TriggerInputs {
  double v1 = 0;             ///< Eq. (19) [m³]
  double v2 = 0;             ///< V21 + V22 [m³] (0 when not predicted)
  double intake_factor = 1;  ///< κ_M of the penetration model for the pile's material [-]
  double boom_pressure = 0;  ///< boom cylinder cap-side pressure [Pa]
};

class ScoopTrigger {
 public:
  virtual ~ScoopTrigger() = default;
  /// One state-machine decision; true once the scoop is to begin. NaN inputs never fire.
  virtual bool Fire(const TriggerInputs& inputs) = 0;
  virtual void Reset() {}
  /// Whether the trigger reads V2 (the cycle computes it only then).
  virtual bool NeedsPrediction() const { return false; }
  virtual std::string Name() const = 0;
};

class PredictedVolumeTrigger : public ScoopTrigger {
 public:
  /// `target_volume` V_t [m³] > 0; throws std::invalid_argument otherwise.
  explicit PredictedVolumeTrigger(double target_volume);
  bool Fire(const TriggerInputs& inputs) override;
  bool NeedsPrediction() const override { return true; }
  std::string Name() const override { return "predicted_volume"; }

 private:
  double target_volume_;
};

class PerceptionTrigger : public ScoopTrigger {
 public:
  explicit PerceptionTrigger(double target_volume);
  bool Fire(const TriggerInputs& inputs) override;
  std::string Name() const override { return "perception"; }

 private:
  double target_volume_;
};

class BoomPressureTrigger : public ScoopTrigger {
 public:
  /// `threshold` [Pa] > 0, `hold_cycles` ≥ 1.
  BoomPressureTrigger(double threshold, int hold_cycles = 2);
  bool Fire(const TriggerInputs& inputs) override;
  void Reset() override { count_ = 0; }
  std::string Name() const override { return "boom_pressure"; }

 private:
  double threshold_;
  int hold_cycles_;
  int count_ = 0;
};

}  // namespace autoshovel::control

// Provenance of a learned model: which machine, and which plant, it was trained on (issue 39,
// item 6: "the learned pieces follow the machine").
//
// A penetration model (penetration_predictor.h: `<stem>.model`, `<stem>.scale`, any
// `<stem>.travel<k>.model`) is fitted to one machine's crowding runs: its speed, arm, valves and
// bucket set how far it travels after the trigger. Driven on another machine it predicts that
// first machine's travel. The trainer therefore writes, beside the model, `<stem>.meta.yaml`:
//
//   # Provenance of the penetration model <stem>: ... (a comment saying what the file is)
//   format: autoshovel-model-provenance 1
//   machine:
//     name: xcmg_968ev
//     description: xcmg_968ev.yaml      # file name only; the SHA-256 below identifies it
//     sha256: <64 hex digits>           # of the description file's bytes (MachineDescription)
//   plant:
//     samples: simulated crowding runs  # or the campaign database the samples came from
//     code: compiled in (generated/xcmg_968ev/)   # or: machine library (<cache path>), or
//                                                 # interpreted (runtime/machines/machine_code.h)
//   trained_by: <the command line>
//
// A sidecar rather than more keys in the .scale file: the .scale reader refuses unknown keys
// (a model written by a newer trainer would be refused by an older build), and the provenance
// is about where the samples came from, not about how to evaluate the model. Written atomically
// (core::WriteFileAtomically) after the model files, so a sidecar never describes a model that
// was not written.
//
// Anything that drives a machine with a model calls ProvenanceMismatch and warns when the model
// was trained on another machine (name or SHA-256 differs) or says nothing about it (no sidecar).
// A warning, not an error: the model may still be close, and a user who knows can go on.
#pragma once

#include <optional>
#include <string>

namespace autoshovel::model {
struct MachineDescription;
}

namespace autoshovel::prediction {

struct ModelProvenance {
  std::string machine;        ///< the machine's name (MachineDescription::name)
  std::string description;    ///< its description's file name (informative)
  std::string sha256;         ///< SHA-256 of the description file's bytes, 64 hex digits
  std::string plant_samples;  ///< where the training samples came from
  std::string plant_code;     ///< which code ran the machine's plant, when simulated
  std::string trained_by;     ///< the training command

  /// The provenance of a model trained on `machine`'s simulated plant (samples, code: see above).
  static ModelProvenance OfSimulatedPlant(const model::MachineDescription& machine,
                                          const std::string& plant_code,
                                          const std::string& trained_by);
};

/// `<path_stem>.meta.yaml`.
std::string ProvenancePath(const std::string& path_stem);

/// Writes `<path_stem>.meta.yaml` atomically. Throws core::OutputError when it cannot be written,
/// std::invalid_argument for a provenance without a machine name or a SHA-256 that is not 64 hex
/// digits.
void SaveProvenance(const std::string& path_stem, const ModelProvenance& provenance);

/// Reads `<path_stem>.meta.yaml`: std::nullopt when there is no such file; throws
/// core::InputError (`file:line:column: key: what is wrong`) for a malformed one.
std::optional<ModelProvenance> LoadProvenance(const std::string& path_stem);

/// "" when the model at `path_stem` was trained on `machine` (same name and description SHA-256);
/// else one line saying what it was trained on (or that it does not say) and how to retrain:
///   penetration model models/prediction/penetration_svr.model was trained on xcmg_968ev (sha
///   3f2a…), not on my_loader (sha 9c01…): retrain with `autoshovel train predictor --machine
///   my_loader.yaml -o STEM` and run with --predictor STEM
/// `machine_argument` is how the user named the machine (a name or a path), for the advice.
/// A malformed sidecar is reported in the line, not thrown: the model itself loaded.
std::string ProvenanceMismatch(const std::string& path_stem,
                               const model::MachineDescription& machine,
                               const std::string& machine_argument);

}  // namespace autoshovel::prediction

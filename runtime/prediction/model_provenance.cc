// Provenance of a learned model (model_provenance.h).
#include "runtime/prediction/model_provenance.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/model/description.h"

namespace autoshovel::prediction {

namespace {

constexpr const char* kFormat = "autoshovel-model-provenance 1";
constexpr std::size_t kShaDigits = 64;

bool IsSha256(const std::string& text) {
  return text.size() == kShaDigits && std::all_of(text.begin(), text.end(), [](char c) {
           return std::isxdigit(static_cast<unsigned char>(c)) &&
                  !std::isupper(static_cast<unsigned char>(c));
         });
}

// A YAML double-quoted scalar: any text, one line.
std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string Short(const std::string& sha) { return sha.substr(0, 12); }

}  // namespace

ModelProvenance ModelProvenance::OfSimulatedPlant(const model::MachineDescription& machine,
                                                  const std::string& plant_code,
                                                  const std::string& trained_by) {
  ModelProvenance p;
  p.machine = machine.name;
  p.description = std::filesystem::path(machine.source_file).filename().string();
  p.sha256 = machine.sha256;
  p.plant_samples = "simulated crowding runs (identification/predictor/crowding_runs.h)";
  if (!machine.overlays.empty()) {
    p.plant_samples += " with the overlays";
    for (const std::string& overlay : machine.overlays) {
      p.plant_samples += " " + std::filesystem::path(overlay).filename().string();
    }
  }
  p.plant_code = plant_code;
  p.trained_by = trained_by;
  return p;
}

std::string ProvenancePath(const std::string& path_stem) { return path_stem + ".meta.yaml"; }

void SaveProvenance(const std::string& path_stem, const ModelProvenance& p) {
  if (p.machine.empty()) {
    throw std::invalid_argument("SaveProvenance: the provenance names no machine");
  }
  if (!IsSha256(p.sha256)) {
    throw std::invalid_argument(
        "SaveProvenance: machine sha256 must be 64 lower-case hex digits, "
        "got '" +
        p.sha256 + "'");
  }
  std::ostringstream y;
  y << "# Provenance of the model " << std::filesystem::path(path_stem).filename().string()
    << ": the machine and the plant it was trained on\n"
    << "# (runtime/prediction/model_provenance.h). Commands that drive a machine with this model\n"
    << "# warn when the machine's name or description SHA-256 differs from these.\n"
    << "format: " << kFormat << "\n"
    << "machine:\n"
    << "  name: " << Quoted(p.machine) << "\n"
    << "  description: " << Quoted(p.description) << "\n"
    << "  sha256: " << p.sha256 << "\n"
    << "plant:\n"
    << "  samples: " << Quoted(p.plant_samples) << "\n"
    << "  code: " << Quoted(p.plant_code) << "\n"
    << "trained_by: " << Quoted(p.trained_by) << "\n";
  core::WriteFileAtomically(ProvenancePath(path_stem), y.str());
}

std::optional<ModelProvenance> LoadProvenance(const std::string& path_stem) {
  const std::string path = ProvenancePath(path_stem);
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return std::nullopt;
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  if (!file.ok()) sink.ThrowIfAny();
  core::MapReader root = core::MapReader::Root(file, nullptr);
  ModelProvenance p;
  const std::string format = root.String("format");
  if (sink.empty() && format != kFormat) {
    root.Error("format", "expected '" + std::string(kFormat) + "', got '" + format + "'");
  }
  core::MapReader machine = root.Map("machine");
  p.machine = machine.String("name");
  p.description = machine.String("description");
  p.sha256 = machine.String("sha256");
  if (!p.sha256.empty() && !IsSha256(p.sha256)) {
    machine.Error("sha256",
                  "expected the 64 lower-case hex digits of a SHA-256, got '" + p.sha256 + "'");
  }
  if (machine.Has("name") && p.machine.empty()) machine.Error("name", "must not be empty");
  machine.Finish();
  core::MapReader plant = root.Map("plant");
  p.plant_samples = plant.String("samples");
  p.plant_code = plant.String("code");
  plant.Finish();
  p.trained_by = root.String("trained_by");
  root.Finish();
  sink.ThrowIfAny();
  return p;
}

std::string ProvenanceMismatch(const std::string& path_stem,
                               const model::MachineDescription& machine,
                               const std::string& machine_argument) {
  const std::string model = path_stem + ".model";
  const std::string argument = machine_argument.empty() ? machine.name : machine_argument;
  const std::string advice = ": retrain with `autoshovel train predictor --machine " + argument +
                             " -o STEM` and run with --predictor STEM";
  std::optional<ModelProvenance> p;
  try {
    p = LoadProvenance(path_stem);
  } catch (const std::exception& e) {
    return "penetration model " + model + ": its provenance cannot be read (" + e.what() +
           "), so it may have been trained on another machine than " + machine.name + advice;
  }
  if (!p) {
    return "penetration model " + model + " has no provenance (" + ProvenancePath(path_stem) +
           "): it may have been trained on another machine than " + machine.name + advice;
  }
  if (p->machine == machine.name && p->sha256 == machine.sha256) return "";
  const std::string trained_on = p->machine + " (sha " + Short(p->sha256) + ")";
  const std::string driven = p->machine == machine.name
                                 ? "this version of " + machine.name + " (sha " +
                                       Short(machine.sha256) + ", " + machine.source_file + ")"
                                 : machine.name + " (sha " + Short(machine.sha256) + ")";
  return "penetration model " + model + " was trained on " + trained_on + ", not on " + driven +
         advice;
}

}  // namespace autoshovel::prediction

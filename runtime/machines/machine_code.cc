#include "runtime/machines/machine_code.h"

#include <iostream>
#include <map>
#include <mutex>

#include "generated/registry.h"
#include "runtime/machines/interpreted_functions.h"
#include "runtime/machines/machine_library.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::machines {

namespace fs = std::filesystem;

namespace {

std::mutex resolve_mutex;
std::map<std::string, MachineCode> resolved;  // by cache root, machine, hash and overlays

// A library that passed every check still has to be the machine the description describes.
std::string Mismatch(const generated::MachineFunctions& f, const model::MachineDescription& m) {
  const model::ModelSizes sizes = model::SizesOf(m);
  if (f.kind == nullptr || std::string(f.kind) != model::ToString(m.kind)) return "kind";
  if (f.num_links != sizes.num_links || f.num_joints != sizes.num_joints ||
      f.num_angles != sizes.num_angles || f.num_params != sizes.num_params ||
      f.num_states != sizes.num_states || f.num_inputs != sizes.num_inputs) {
    return "vector sizes";
  }
  if (f.num_actuators != static_cast<int>(m.hydraulics.actuators.size())) return "actuators";
  return "";
}

}  // namespace

const char* ToString(CodeSource source) {
  switch (source) {
    case CodeSource::kCompiledIn:
      return "compiled in";
    case CodeSource::kLibrary:
      return "machine library";
    case CodeSource::kInterpreted:
      return "interpreted";
  }
  return "?";
}

MachineCode ResolveMachineCode(const model::MachineDescription& machine,
                               const ResolveOptions& options) {
  const generated::MachineFunctions* built_in = generated::FindMachine(machine.name);
  if (!machine.overlay_code_keys.empty()) {
    // Code generated from the base file has these values compiled in and would silently run
    // without them.
    std::lock_guard<std::mutex> lock(resolve_mutex);
    std::string key = "interpreted\n" + machine.name + '\n' + machine.sha256;
    for (const std::string& overlay : machine.overlays) key += '\n' + overlay;
    if (const auto it = resolved.find(key); it != resolved.end()) return it->second;
    const generated::MachineFunctions& f = InterpretedFunctions(machine);
    if (options.notes != nullptr) {
      *options.notes << "autoshovel: machine '" << machine.name
                     << "': using the interpreted model (slower): an overlay sets values the "
                        "generated code compiles in ("
                     << machine.overlay_code_keys.front()
                     << (machine.overlay_code_keys.size() > 1
                             ? " and " + std::to_string(machine.overlay_code_keys.size() - 1) +
                                   " more"
                             : std::string())
                     << ")\n";
    }
    return resolved[key] = {&f, CodeSource::kInterpreted, "an overlay changes compiled-in values"};
  }
  if (built_in != nullptr && machine.sha256 == built_in->source_sha256) {
    return {built_in, CodeSource::kCompiledIn, "generated/" + machine.name + "/"};
  }
  const std::string describe = "machine '" + machine.name + "' (" + machine.source_file + ")";
  const std::string gen = "autoshovel gen " + machine.source_file;
  fs::path root = options.cache_root;
  if (root.empty()) {
    try {
      root = DefaultCacheRoot();
    } catch (const std::exception& e) {
      throw MachineCodeError(describe + ": " + e.what());
    }
  }
  std::string key = root.string() + '\n' + machine.name + '\n' + machine.sha256;
  for (const std::string& overlay : machine.overlays) key += '\n' + overlay;

  std::lock_guard<std::mutex> lock(resolve_mutex);
  if (const auto it = resolved.find(key); it != resolved.end()) return it->second;

  const LibraryLoad load = LoadMachineLibrary(machine.name, machine.sha256, root);
  if (load.status == LibraryCheck::Status::kValid) {
    const std::string mismatch = Mismatch(*load.functions, machine);
    if (!mismatch.empty()) {
      throw MachineCodeError(describe + ": machine library " + load.library.string() +
                             " refused: its " + mismatch +
                             " differ from the description's; run: " + gen);
    }
    return resolved[key] = {load.functions, CodeSource::kLibrary, load.library.string()};
  }
  if (load.status == LibraryCheck::Status::kRefused) {
    throw MachineCodeError(describe + ": machine library refused: " + load.reason +
                           " (rebuild it: " + gen + ")");
  }
  std::string searched;
  const bool compiler = options.compiler_present.has_value() ? *options.compiler_present
                                                             : FindCompiler(&searched).has_value();
  if (!compiler) {
    const generated::MachineFunctions& f = InterpretedFunctions(machine);
    if (options.notes != nullptr) {
      *options.notes << "autoshovel: " << describe
                     << ": using the interpreted model: no C++ compiler found"
                     << (searched.empty() ? "" : " (searched " + searched + ")")
                     << "; slower. With a compiler (scripts/setup installs one): " << gen << '\n';
    }
    return resolved[key] = {&f, CodeSource::kInterpreted, "no C++ compiler found"};
  }
  std::string message = describe + " has no compiled code: " + load.reason;
  if (built_in != nullptr) {
    message += " (the built-in '" + machine.name +
               "' was generated from another version of the file, SHA-256 " +
               built_in->source_sha256 + ")";
  }
  throw MachineCodeError(message + "; run: " + gen);
}

const generated::MachineFunctions& MachineFunctionsFor(const model::MachineDescription& machine) {
  ResolveOptions options;
  options.notes = &std::cerr;
  return *ResolveMachineCode(machine, options).functions;
}

}  // namespace autoshovel::machines

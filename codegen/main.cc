// autoshovel-codegen: machine descriptions in, C++ out. Built first; the `regen` target runs it
// over models/ into generated/. Users normally call it as `autoshovel gen`.
#include <sys/personality.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "codegen/generate.h"

namespace {

constexpr const char* kUsage =
    "usage: autoshovel-codegen [--clean] [--compile [--cache DIR]] [--materials DIR] -o OUTPUT_DIR "
    "(--models MODELS_DIR | DESCRIPTION.yaml...)\n"
    "  Validates machine descriptions and writes their generated C++ to OUTPUT_DIR/<machine>/,\n"
    "  then rewrites OUTPUT_DIR's registry and CMakeLists.txt.\n"
    "  --models DIR     every description under DIR (except materials/ and scenarios/)\n"
    "  --materials DIR  material files (default: <description dir>/../materials)\n"
    "  --clean          remove machine folders no description produced\n"
    "  --compile        also compile each machine into a machine library in the per-user cache\n"
    "                   ($CXX or c++; see runtime/machines/machine_cache.h), as `autoshovel gen`\n"
    "  --cache DIR      machine library cache (default: $AUTOSHOVEL_MACHINE_CACHE, else\n"
    "                   ${XDG_CACHE_HOME:-~/.cache}/autoshovel/machines)\n"
    "  --expect-abi TAG the ABI tag of the autoshovel that will load the library (gen passes it)\n";

// GiNaC orders the terms of sums and products by hashes that mix in the addresses of its type
// information, so with address-space randomisation every run prints a different (equivalent)
// expression, and even rounds float constants in a different order. Generated code must be
// byte-identical from run to run (tests/codegen/regeneration_check.cmake), so the generator
// re-executes itself once with randomisation off: the same binary on the same system then lays
// out memory, and so orders terms, the same way every time.
void ReexecWithoutAddressRandomisation(char** argv) {
  const int current = personality(0xffffffff);
  if (current == -1 || (current & ADDR_NO_RANDOMIZE) != 0) return;
  if (personality(static_cast<unsigned long>(current) | ADDR_NO_RANDOMIZE) == -1) return;
  execv("/proc/self/exe", argv);
  // execv only returns on failure: carry on, output may then differ in term order.
  std::cerr << "autoshovel-codegen: warning: could not disable address randomisation; "
               "generated term order may vary between runs\n";
}

}  // namespace

int main(int argc, char** argv) {
  ReexecWithoutAddressRandomisation(argv);
  autoshovel::codegen::GenerateRequest request;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= argc) {
        std::cerr << flag << " needs a value\n" << kUsage;
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (arg == "-o" || arg == "--output") {
      request.output_dir = value("-o");
    } else if (arg == "--models") {
      request.models_dir = value("--models");
    } else if (arg == "--materials") {
      request.materials_dir = value("--materials");
    } else if (arg == "--clean") {
      request.clean = true;
    } else if (arg == "--compile") {
      request.compile = true;
    } else if (arg == "--cache") {
      request.cache_root = value("--cache");
    } else if (arg == "--expect-abi") {
      request.expected_abi = value("--expect-abi");
    } else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "unknown option " << arg << "\n" << kUsage;
      return 2;
    } else {
      request.descriptions.push_back(arg);
    }
  }
  if (request.output_dir.empty()) {
    std::cerr << "missing -o OUTPUT_DIR\n" << kUsage;
    return 2;
  }
  return autoshovel::codegen::Generate(request, std::cout, std::cerr);
}

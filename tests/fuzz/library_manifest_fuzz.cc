// Fuzz target: the machine library manifest reader (runtime/machines/machine_cache.h), which
// decides, with the permission checks, whether compiled code is loaded. Its only documented
// refusal is core::InputError located in the manifest; an accepted manifest must hold hashes of
// 64 hex digits and a library named lib<machine>.so.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/machines/machine_cache.h"
#include "tests/fuzz/refusal.h"

namespace {

bool IsHash(const std::string& text) {
  if (text.size() != 64) return false;
  for (const char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = "fuzz/manifest";
  try {
    const machines::LibraryManifest m = machines::ParseManifest(text, path);
    if (!IsHash(m.source_sha256) || !IsHash(m.library_sha256) ||
        m.library != machines::LibraryFileName(m.machine)) {
      std::fprintf(stderr, "accepted a manifest with bad hashes or library name\n");
      std::abort();
    }
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, text);
  }
  return 0;
}

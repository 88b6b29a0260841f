#include "runtime/plant/world.h"

namespace autoshovel::plant {

const char* ToString(Lighting lighting) {
  switch (lighting) {
    case Lighting::kBright:
      return "bright";
    case Lighting::kDim:
      return "dim";
    case Lighting::kNormal:
      break;
  }
  return "normal";
}

std::optional<Lighting> ParseLighting(std::string_view name) {
  for (Lighting l : {Lighting::kNormal, Lighting::kBright, Lighting::kDim}) {
    if (name == ToString(l)) return l;
  }
  return std::nullopt;
}

}  // namespace autoshovel::plant

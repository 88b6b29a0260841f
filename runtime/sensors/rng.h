// The random engine of every simulated sensor. One engine, seeded by the caller, is passed by
// reference through a frame's simulation, so the same seed and the same calls give
// byte-identical data (the draws' order is fixed by the scan pattern and the pixel order, not by
// timing or threads). std::mt19937_64 and libstdc++'s distributions are deterministic across
// runs of one build; they are not promised identical across standard libraries.
#pragma once

#include <cstdint>
#include <random>

namespace autoshovel::sensors {

using Rng = std::mt19937_64;

}  // namespace autoshovel::sensors

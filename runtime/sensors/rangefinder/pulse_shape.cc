#include "runtime/sensors/rangefinder/pulse_shape.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::sensors {
namespace {

// FWHM / σ of a Gaussian and FWHM / τ of a sech².
const double kGaussianFwhmPerSigma = 2.0 * std::sqrt(2.0 * std::numbers::ln2);
const double kSech2FwhmPerTau = 2.0 * std::acosh(std::numbers::sqrt2);
// The level at which Support() truncates the pulse.
constexpr double kSupportLevel = 1e-6;

}  // namespace

const char* ToString(PulseShapeKind kind) {
  switch (kind) {
    case PulseShapeKind::kGaussian:
      return "gaussian";
    case PulseShapeKind::kSech2:
      return "sech2";
  }
  return "unknown";
}

PulseShape::PulseShape(PulseShapeKind kind, double fwhm) : kind_(kind), fwhm_(fwhm) {
  if (!std::isfinite(fwhm) || fwhm <= 0) {
    throw std::invalid_argument("PulseShape: fwhm must be finite and positive, got " +
                                std::to_string(fwhm));
  }
  width_ =
      kind == PulseShapeKind::kGaussian ? fwhm / kGaussianFwhmPerSigma : fwhm / kSech2FwhmPerTau;
}

double PulseShape::Value(double t) const {
  const double x = t / width_;
  if (kind_ == PulseShapeKind::kGaussian) return std::exp(-0.5 * x * x);
  // sech²(x) = 4 e^{−2|x|} / (1 + e^{−2|x|})², written so that large |x| cannot overflow.
  const double e = std::exp(-2.0 * std::abs(x));
  return 4.0 * e / ((1.0 + e) * (1.0 + e));
}

double PulseShape::Integral() const {
  // ∫ exp(−t²/2σ²) dt = σ·sqrt(2π);  ∫ sech²(t/τ) dt = 2τ.
  return kind_ == PulseShapeKind::kGaussian ? width_ * std::sqrt(2.0 * std::numbers::pi)
                                            : 2.0 * width_;
}

double PulseShape::Support() const { return HalfWidthAt(kSupportLevel); }

double PulseShape::HalfWidthAt(double fraction) const {
  if (!(fraction > 0 && fraction <= 1)) {
    throw std::invalid_argument("PulseShape::HalfWidthAt: fraction must be in (0, 1], got " +
                                std::to_string(fraction));
  }
  if (kind_ == PulseShapeKind::kGaussian) return width_ * std::sqrt(-2.0 * std::log(fraction));
  return width_ * std::acosh(1.0 / std::sqrt(fraction));
}

}  // namespace autoshovel::sensors

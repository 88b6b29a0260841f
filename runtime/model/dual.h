// A minimal forward-mode dual number over any scalar S (double, Eigen::AutoDiffScalar, ...).
//
// The reference model needs first derivatives of cylinder lengths (the lever arms) inside a
// right-hand side that is itself differentiated by Eigen's AutoDiffScalar for the plant
// Jacobian. Nesting AutoDiffScalar in Eigen matrices needs NumTraits plumbing; this struct keeps
// the nesting to the few operations the geometry uses.
#pragma once

#include <cmath>

namespace autoshovel::model {

template <typename S>
struct Dual {
  S v;  ///< value
  S d;  ///< derivative along the seeded direction
  Dual() : v(0.0), d(0.0) {}
  Dual(double value) : v(value), d(0.0) {}  // NOLINT: constants promote implicitly
  Dual(S value, S derivative) : v(value), d(derivative) {}
};

template <typename S>
Dual<S> operator+(const Dual<S>& a, const Dual<S>& b) {
  return {a.v + b.v, a.d + b.d};
}
template <typename S>
Dual<S> operator-(const Dual<S>& a, const Dual<S>& b) {
  return {a.v - b.v, a.d - b.d};
}
template <typename S>
Dual<S> operator-(const Dual<S>& a) {
  return {-a.v, -a.d};
}
template <typename S>
Dual<S> operator*(const Dual<S>& a, const Dual<S>& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d};
}
template <typename S>
Dual<S> operator/(const Dual<S>& a, const Dual<S>& b) {
  return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)};
}
template <typename S>
Dual<S> operator*(double a, const Dual<S>& b) {
  return {a * b.v, a * b.d};
}
template <typename S>
Dual<S> operator*(const Dual<S>& a, double b) {
  return {a.v * b, a.d * b};
}
template <typename S>
Dual<S> operator/(const Dual<S>& a, double b) {
  return {a.v / b, a.d / b};
}
template <typename S>
Dual<S> operator+(const Dual<S>& a, double b) {
  return {a.v + b, a.d};
}
template <typename S>
Dual<S> operator-(const Dual<S>& a, double b) {
  return {a.v - b, a.d};
}
template <typename S>
Dual<S> operator-(double a, const Dual<S>& b) {
  return {a - b.v, -b.d};
}
template <typename S>
Dual<S> operator+(double a, const Dual<S>& b) {
  return {a + b.v, b.d};
}
template <typename S>
Dual<S>& operator+=(Dual<S>& a, const Dual<S>& b) {
  return a = a + b;
}
template <typename S>
bool operator>(const Dual<S>& a, const Dual<S>& b) {
  return a.v > b.v;
}

template <typename S>
Dual<S> operator/(double a, const Dual<S>& b) {
  return {a / b.v, -a * b.d / (b.v * b.v)};
}
template <typename S>
Dual<S> pow(const Dual<S>& a, double exponent) {
  using std::pow;
  return {pow(a.v, exponent), exponent * pow(a.v, exponent - 1.0) * a.d};
}

template <typename S>
Dual<S> sin(const Dual<S>& a) {
  using std::cos;
  using std::sin;
  return {sin(a.v), cos(a.v) * a.d};
}
template <typename S>
Dual<S> cos(const Dual<S>& a) {
  using std::cos;
  using std::sin;
  return {cos(a.v), -sin(a.v) * a.d};
}
template <typename S>
Dual<S> sqrt(const Dual<S>& a) {
  using std::sqrt;
  const S root = sqrt(a.v);
  return {root, a.d / (2.0 * root)};
}
template <typename S>
Dual<S> atan2(const Dual<S>& y, const Dual<S>& x) {
  using std::atan2;
  const S r2 = x.v * x.v + y.v * y.v;
  return {atan2(y.v, x.v), (x.v * y.d - y.v * x.d) / r2};
}

}  // namespace autoshovel::model

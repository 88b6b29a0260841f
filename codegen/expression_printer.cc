#include "codegen/expression_printer.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>
#include <stdexcept>

namespace autoshovel::codegen {
namespace {

using GiNaC::ex;
using GiNaC::is_a;

using TempMap = std::map<ex, std::string, GiNaC::ex_is_less>;

// GiNaC orders the operands of sums and products by hashes that include addresses of type
// information in libginac, so the order changes from run to run (ASLR). Generated files must be
// byte-identical across runs: operands are printed and visited in the order of a structural
// hash computed from names, values and shape only.
class CanonicalOrder {
 public:
  std::uint64_t Hash(const ex& e) {
    if (const auto it = memo_.find(e); it != memo_.end()) return it->second;
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](std::uint64_t v) { h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2); };
    auto mix_text = [&mix](const std::string& text) {
      std::uint64_t t = 1469598103934665603ull;
      for (const unsigned char c : text) t = (t ^ c) * 1099511628211ull;
      mix(t);
    };
    if (is_a<GiNaC::symbol>(e)) {
      mix_text("s" + GiNaC::ex_to<GiNaC::symbol>(e).get_name());
    } else if (is_a<GiNaC::numeric>(e)) {
      mix_text("n" + DoubleLiteral(GiNaC::ex_to<GiNaC::numeric>(e).to_double()));
    } else {
      const bool commutative = is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e);
      mix_text(is_a<GiNaC::add>(e)        ? "add"
               : is_a<GiNaC::mul>(e)      ? "mul"
               : is_a<GiNaC::power>(e)    ? "pow"
               : is_a<GiNaC::function>(e) ? "f" + GiNaC::ex_to<GiNaC::function>(e).get_name()
                                          : "?");
      std::vector<std::uint64_t> children;
      for (std::size_t i = 0; i < e.nops(); ++i) children.push_back(Hash(e.op(i)));
      if (commutative) std::sort(children.begin(), children.end());
      for (const auto c : children) mix(c);
    }
    memo_.emplace(e, h);
    return h;
  }

  /// Operands of `e` in canonical order (sums and products sorted, others as they are).
  std::vector<ex> Operands(const ex& e) {
    std::vector<ex> ops;
    for (std::size_t i = 0; i < e.nops(); ++i) ops.push_back(e.op(i));
    if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e)) {
      std::stable_sort(ops.begin(), ops.end(),
                       [this](const ex& a, const ex& b) { return Hash(a) < Hash(b); });
    }
    return ops;
  }

 private:
  std::map<ex, std::uint64_t, GiNaC::ex_is_less> memo_;
};

bool IsLeaf(const ex& e) { return is_a<GiNaC::symbol>(e) || is_a<GiNaC::numeric>(e); }

bool IsIntegerPower(const ex& e, long& n) {
  if (!is_a<GiNaC::power>(e)) return false;
  const ex exponent = e.op(1);
  if (!is_a<GiNaC::numeric>(exponent)) return false;
  const GiNaC::numeric num = GiNaC::ex_to<GiNaC::numeric>(exponent);
  if (!num.is_integer()) return false;
  n = num.to_long();
  return true;
}

class Printer {
 public:
  Printer(const TempMap* temps, CanonicalOrder* order) : temps_(temps), order_(order) {}

  std::string Print(const ex& e, bool top = false) const {
    if (!top && temps_ != nullptr) {
      if (const auto it = temps_->find(e); it != temps_->end()) return it->second;
    }
    if (is_a<GiNaC::symbol>(e)) return GiNaC::ex_to<GiNaC::symbol>(e).get_name();
    if (is_a<GiNaC::numeric>(e)) return Number(GiNaC::ex_to<GiNaC::numeric>(e));
    if (is_a<GiNaC::add>(e)) return Add(e);
    if (is_a<GiNaC::mul>(e)) return Mul(e);
    if (is_a<GiNaC::power>(e)) return Power(e);
    if (is_a<GiNaC::function>(e)) return Function(e);
    std::ostringstream unknown;
    unknown << e;
    throw std::runtime_error("codegen: cannot print expression " + unknown.str());
  }

 private:
  static std::string Number(const GiNaC::numeric& n) {
    if (!n.is_real()) throw std::runtime_error("codegen: complex constant in expression");
    const double value = n.to_double();
    const std::string text = DoubleLiteral(value);
    return value < 0 ? "(" + text + ")" : text;
  }

  // An operand inside a product: sums need parentheses.
  std::string Factor(const ex& e) const {
    const std::string text = Print(e);
    if (temps_ != nullptr && temps_->count(e) > 0) return text;
    if (is_a<GiNaC::add>(e)) return "(" + text + ")";
    return text;
  }

  std::string Add(const ex& e) const {
    std::string out;
    for (const ex& term : order_->Operands(e)) {
      // A product with a negative numeric coefficient prints as subtraction.
      if (is_a<GiNaC::mul>(term) && (temps_ == nullptr || temps_->count(term) == 0)) {
        const ex coefficient = term.op(term.nops() - 1);  // GiNaC keeps it last
        if (is_a<GiNaC::numeric>(coefficient) &&
            GiNaC::ex_to<GiNaC::numeric>(coefficient).is_negative()) {
          const ex positive = -term;
          out += (out.empty() ? "-" : " - ") + Factor(positive);
          continue;
        }
      }
      if (is_a<GiNaC::numeric>(term) && GiNaC::ex_to<GiNaC::numeric>(term).is_negative()) {
        out += (out.empty() ? "-" : " - ") +
               DoubleLiteral(-GiNaC::ex_to<GiNaC::numeric>(term).to_double());
        continue;
      }
      out += (out.empty() ? "" : " + ") + Print(term);
    }
    return "(" + out + ")";
  }

  std::string Mul(const ex& e) const {
    std::string numerator, denominator;
    for (const ex& factor : order_->Operands(e)) {
      long n = 0;
      if (IsIntegerPower(factor, n) && n < 0 && (temps_ == nullptr || temps_->count(factor) == 0)) {
        const std::string base = Factor(factor.op(0));
        std::string product = base;
        for (long k = 1; k < -n; ++k) product += " * " + base;
        denominator += (denominator.empty() ? "" : " * ") + product;
        continue;
      }
      numerator += (numerator.empty() ? "" : " * ") + Factor(factor);
    }
    if (numerator.empty()) numerator = "1.0";
    if (denominator.empty()) return numerator;
    return numerator + " / (" + denominator + ")";
  }

  std::string Power(const ex& e) const {
    const ex base = e.op(0);
    const ex exponent = e.op(1);
    long n = 0;
    if (IsIntegerPower(e, n)) {
      const std::string b = Factor(base);
      if (n == 0) return "1.0";
      std::string product = b;
      for (long k = 1; k < std::labs(n); ++k) product += " * " + b;
      if (n > 0) return n == 1 ? product : "(" + product + ")";
      return "(1.0 / (" + product + "))";
    }
    if (exponent.is_equal(GiNaC::numeric(1, 2))) return "sqrt(" + Print(base) + ")";
    if (exponent.is_equal(GiNaC::numeric(-1, 2))) return "(1.0 / sqrt(" + Print(base) + "))";
    return "pow(" + Print(base) + ", " + Print(exponent) + ")";
  }

  std::string Function(const ex& e) const {
    const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
    std::string args;
    for (std::size_t i = 0; i < e.nops(); ++i) args += (i ? ", " : "") + Print(e.op(i));
    if (name == "sin" || name == "cos" || name == "tan" || name == "atan2" || name == "acos" ||
        name == "asin" || name == "atan" || name == "exp" || name == "log" || name == "abs") {
      return name + "(" + args + ")";
    }
    throw std::runtime_error("codegen: unsupported function " + name);
  }

  const TempMap* temps_;
  CanonicalOrder* order_;
};

// Counts how often each composite subexpression is reached from the outputs, visiting each
// distinct subexpression's children once (so counts are uses, not tree paths).
void Count(const ex& e, std::map<ex, int, GiNaC::ex_is_less>& uses, std::vector<ex>& post_order,
           CanonicalOrder& order) {
  if (IsLeaf(e)) return;
  int& count = uses[e];
  ++count;
  if (count > 1) return;
  for (const ex& child : order.Operands(e)) Count(child, uses, post_order, order);
  // Bases of integer powers and of sqrt print more than once or are costly: count them twice.
  long n = 0;
  if (IsIntegerPower(e, n) && std::labs(n) >= 2 && !IsLeaf(e.op(0))) ++uses[e.op(0)];
  post_order.push_back(e);
}

}  // namespace

std::string DoubleLiteral(double value) {
  if (!std::isfinite(value)) throw std::runtime_error("codegen: non-finite constant");
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";
  return text;
}

std::string PrintExpression(const ex& e) {
  CanonicalOrder order;
  return Printer(nullptr, &order).Print(e, true);
}

std::string PrintAssignments(const std::vector<Assignment>& assignments, const std::string& scalar,
                             int indent) {
  CanonicalOrder order;
  std::map<ex, int, GiNaC::ex_is_less> uses;
  std::vector<ex> post_order;
  for (const auto& a : assignments) Count(a.value, uses, post_order, order);
  TempMap temps;
  const std::string pad(indent, ' ');
  std::string out;
  Printer printer(&temps, &order);
  int next = 0;
  for (const ex& e : post_order) {
    if (uses[e] < 2) continue;
    // Negations are cheap and print fine inline.
    if (is_a<GiNaC::mul>(e) && e.nops() == 2 && is_a<GiNaC::numeric>(e.op(1)) &&
        e.op(1).is_equal(-1)) {
      continue;
    }
    const std::string name = "t" + std::to_string(next++);
    out += pad + "const " + scalar + " " + name + " = " + printer.Print(e, true) + ";\n";
    temps.emplace(e, name);
  }
  // A constant assigned to a non-double scalar is wrapped in its constructor: ceres::Jet has no
  // assignment or copy-initialisation from a double.
  const bool wrap_constants = scalar != "double";
  for (const auto& a : assignments) {
    const std::string value = printer.Print(a.value);
    out += pad + a.target + " = " +
           (wrap_constants && is_a<GiNaC::numeric>(a.value) ? scalar + "(" + value + ")" : value) +
           ";\n";
  }
  return out;
}

}  // namespace autoshovel::codegen

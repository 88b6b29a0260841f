// Prints GiNaC expressions as plain C++ statements, with common-subexpression elimination.
//
// GiNaC's own C output (`csrc`) repeats shared subexpressions (a Jacobian of a linkage repeats
// the same square roots dozens of times), prints integers that ceres::Jet cannot multiply with,
// and uses pow() for squares. This printer walks the expression DAG of all outputs of one
// function together, hoists every non-trivial subexpression used more than once into a
// `const T tN = ...;`, and prints numbers as doubles.
#pragma once

#include <ginac/ginac.h>

#include <string>
#include <utility>
#include <vector>

namespace autoshovel::codegen {

struct Assignment {
  std::string target;  ///< C++ lvalue, e.g. `pose[0]`
  GiNaC::ex value;
};

/// C++ statements computing every assignment, indented by `indent` spaces. `scalar` is the
/// type of temporaries (`T` in templates, `double` otherwise).
std::string PrintAssignments(const std::vector<Assignment>& assignments, const std::string& scalar,
                             int indent = 2);

/// One expression without temporaries (for short expressions, e.g. constants).
std::string PrintExpression(const GiNaC::ex& e);

/// A double literal that reads back exactly and always has a decimal point or exponent.
std::string DoubleLiteral(double value);

}  // namespace autoshovel::codegen

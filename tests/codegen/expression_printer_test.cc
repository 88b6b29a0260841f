// The printer's output is valid C++ with the same value as GiNaC's own evaluation.
#include "codegen/expression_printer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace autoshovel::codegen {
namespace {

TEST(ExpressionPrinter, DoubleLiteralsRoundTripAndLookLikeDoubles) {
  for (double value : {0.0, 1.0, -2.0, 3.11, 1e-300, 6.02214076e23, 0.1 + 0.2}) {
    const std::string text = DoubleLiteral(value);
    EXPECT_EQ(std::stod(text), value) << text;
    EXPECT_NE(text.find_first_of(".e"), std::string::npos) << text;
  }
  EXPECT_THROW(DoubleLiteral(std::nan("")), std::runtime_error);
}

TEST(ExpressionPrinter, SharedSubexpressionsBecomeTemporaries) {
  const GiNaC::symbol x("x[0]"), y("x[1]");
  const GiNaC::ex shared = GiNaC::sin(x + y);
  const std::string code =
      PrintAssignments({{"out[0]", shared * 2}, {"out[1]", shared + GiNaC::pow(y, 2)}}, "double");
  // sin(x + y) is computed once, into a temporary.
  EXPECT_EQ(code.find("sin("), code.rfind("sin(")) << code;
  EXPECT_NE(code.find("const double t0 = "), std::string::npos) << code;
  EXPECT_EQ(code.find("pow("), std::string::npos) << code;  // squares are products
}

TEST(ExpressionPrinter, FractionalPowersUseSqrt) {
  const GiNaC::symbol x("x");
  EXPECT_EQ(PrintExpression(GiNaC::sqrt(x)), "sqrt(x)");
  EXPECT_EQ(PrintExpression(GiNaC::pow(x, -1)), "(1.0 / (x))");
  EXPECT_EQ(PrintExpression(GiNaC::pow(x, GiNaC::numeric(1, 4))), "pow(x, 0.25)");
}

}  // namespace
}  // namespace autoshovel::codegen

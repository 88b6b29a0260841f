#include "identification/hydraulics/column_expression.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace autoshovel::identification {

namespace {

bool IsDigit(char c) { return c >= '0' && c <= '9'; }
bool IsBlank(char c) { return c == ' ' || c == '\t'; }

// Letters, "_", "." and "/" start a name; digits continue it. Bytes above 127 (UTF-8 or a code
// page's letters in a channel name) count as letters.
bool IsNameStart(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '/' || c == '.' ||
         static_cast<unsigned char>(c) >= 128;
}
bool IsNameChar(char c) { return IsNameStart(c) || IsDigit(c); }

// Digits only, as a 1-based column number; 0 for a number too large to be a column.
long ColumnNumber(const std::string& digits) { return digits.size() > 9 ? 0 : std::stol(digits); }

class Parser {
 public:
  explicit Parser(const std::string& text) : text_(text) {}

  ColumnExpression Parse() {
    ColumnExpression expression;
    expression.text = text_;
    SkipBlanks();
    double sign = 1;
    if (At('+') || At('-')) {
      sign = At('-') ? -1 : 1;
      ++at_;
    }
    while (true) {
      Term(sign, expression);
      SkipBlanks();
      if (at_ == text_.size()) break;
      if (At('*')) Fail("expected + or - before '*' (the factor comes first: 2*name)");
      if (!At('+') && !At('-')) {
        Fail(std::string("expected + or - before '") + text_[at_] + "'" + NameHint());
      }
      sign = At('-') ? -1 : 1;
      ++at_;
    }
    if (expression.terms.empty()) {
      throw ColumnExpressionError(1,
                                  "no column in it (numbers alone are constants; name a column, "
                                  "or give its number as $N)");
    }
    return expression;
  }

 private:
  bool At(char c) const { return at_ < text_.size() && text_[at_] == c; }
  void SkipBlanks() {
    while (at_ < text_.size() && IsBlank(text_[at_])) ++at_;
  }
  [[noreturn]] void Fail(const std::string& message) const {
    throw ColumnExpressionError(at_ + 1, message);
  }
  // After an unexpected character inside a run of name characters: names with other characters
  // are quoted.
  std::string NameHint() const {
    std::size_t before = at_;
    while (before > 0 && IsBlank(text_[before - 1])) --before;
    return before > 0 && IsNameChar(text_[before - 1])
               ? " (a name with other characters than letters, digits, _ . / is quoted: "
                 "'like this')"
               : "";
  }
  std::string After() const {
    return at_ == 0 ? "" : std::string(" after '") + text_[at_ - 1] + "'";
  }

  void Term(double sign, ColumnExpression& expression) {
    SkipBlanks();
    if (at_ == text_.size()) Fail("expected a column name, $N or a number" + After());
    if (IsDigit(text_[at_]) || (At('.') && at_ + 1 < text_.size() && IsDigit(text_[at_ + 1]))) {
      const double number = Number();
      SkipBlanks();
      if (!At('*')) {
        if (at_ < text_.size() && !At('+') && !At('-')) {
          Fail("expected *, + or - after the number " + text_.substr(start_, end_ - start_));
        }
        expression.offset += sign * number;
        return;
      }
      ++at_;
      SkipBlanks();
      if (at_ == text_.size()) Fail("expected a column after '*'");
      sign *= number;
    }
    if (At('-')) {
      sign = -sign;
      ++at_;
      SkipBlanks();
    }
    expression.terms.push_back({sign, Reference()});
  }

  // digits [. digits] [e [+-] digits], or . digits ...
  double Number() {
    start_ = at_;
    while (at_ < text_.size() && IsDigit(text_[at_])) ++at_;
    if (At('.')) {
      ++at_;
      while (at_ < text_.size() && IsDigit(text_[at_])) ++at_;
    }
    if (At('e') || At('E')) {
      std::size_t exponent = at_ + 1;
      if (exponent < text_.size() && (text_[exponent] == '+' || text_[exponent] == '-')) {
        ++exponent;
      }
      if (exponent < text_.size() && IsDigit(text_[exponent])) {
        at_ = exponent;
        while (at_ < text_.size() && IsDigit(text_[at_])) ++at_;
      }
    }
    end_ = at_;
    const std::string spelled = text_.substr(start_, end_ - start_);
    const double value = std::strtod(spelled.c_str(), nullptr);
    if (!std::isfinite(value)) {
      throw ColumnExpressionError(start_ + 1, "the number " + spelled + " is out of range");
    }
    return value;
  }

  ColumnReference Reference() {
    ColumnReference reference;
    reference.position = at_ + 1;
    const std::size_t start = at_;
    if (at_ == text_.size()) Fail("expected a column name or $N" + After());
    const char c = text_[at_];
    if (c == '$') {
      ++at_;
      while (at_ < text_.size() && IsDigit(text_[at_])) ++at_;
      const std::string digits = text_.substr(start + 1, at_ - start - 1);
      if (digits.empty()) Fail("expected a column number after '$'");
      reference.by_number = true;
      reference.number = ColumnNumber(digits);
      if (std::all_of(digits.begin(), digits.end(), [](char d) { return d == '0'; })) {
        throw ColumnExpressionError(start + 1, "columns are numbered from 1, got $" + digits);
      }
    } else if (c == '\'' || c == '"') {
      const std::size_t close = text_.find(c, at_ + 1);
      if (close == std::string::npos) Fail(std::string("the quote ") + c + " is not closed");
      // (Fail points at the opening quote: at_ has not moved past it.)
      reference.name = text_.substr(at_ + 1, close - at_ - 1);
      if (reference.name.empty()) Fail("an empty name");
      at_ = close + 1;
    } else if (IsNameStart(c)) {
      while (at_ < text_.size() && IsNameChar(text_[at_])) ++at_;
      reference.name = text_.substr(start, at_ - start);
    } else {
      Fail(std::string("expected a column name, $N or a number, got '") + c + "'");
    }
    reference.text = text_.substr(start, at_ - start);
    return reference;
  }

  const std::string& text_;
  std::size_t at_ = 0;
  std::size_t start_ = 0, end_ = 0;  // the last number read
};

}  // namespace

ColumnExpression ParseColumnExpression(const std::string& value) {
  const std::size_t begin = value.find_first_not_of(" \t");
  const std::string text = begin == std::string::npos
                               ? ""
                               : value.substr(begin, value.find_last_not_of(" \t") - begin + 1);
  if (text.empty()) throw ColumnExpressionError(1, "empty (expected a column name or number)");
  ColumnReference reference;
  reference.text = text;
  reference.position = 1;
  if (std::all_of(text.begin(), text.end(), IsDigit)) {
    reference.by_number = true;
    reference.number = ColumnNumber(text);
    return {text, {{1, reference}}, 0};
  }
  if (text.find_first_of("+-*$'\"") == std::string::npos) {
    reference.name = text;
    return {text, {{1, reference}}, 0};
  }
  return Parser(text).Parse();
}

}  // namespace autoshovel::identification

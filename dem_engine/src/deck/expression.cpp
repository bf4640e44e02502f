// Equal-style formula evaluation (LAMMPS/LIGGGHTS `variable NAME equal FORMULA`).
//
// Precedence, highest first: unary - and !, ^ (left to right, as LAMMPS), * / %, + -, < <= > >=,
// == !=, &&, ||. As in LAMMPS, unary minus binds tighter than ^, so -2^2 is 4.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "deck/errors.h"
#include "deck/variables.h"

namespace dem {

namespace {

constexpr double kPi = 3.14159265358979323846;
// v_NAME references may nest this deep; deeper means a reference cycle.
constexpr int kMaxVariableDepth = 32;
// Parentheses/unary operators may nest this deep across all formulas being evaluated at once;
// the limit keeps the recursive parser off the end of the stack.
constexpr int kMaxNesting = 400;

thread_local int variable_depth = 0;
thread_local int nesting_depth = 0;

// Counts nesting on a shared counter; the caller builds the error text only on failure.
class DepthGuard {
 public:
  DepthGuard(int& counter, int limit) : counter_(counter), exceeded_(counter >= limit) {
    if (!exceeded_) ++counter_;
  }
  ~DepthGuard() {
    if (!exceeded_) --counter_;
  }
  DepthGuard(const DepthGuard&) = delete;
  DepthGuard& operator=(const DepthGuard&) = delete;
  bool exceeded() const { return exceeded_; }

 private:
  int& counter_;
  bool exceeded_;
};

bool is_identifier_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

bool is_identifier_char(char c) { return is_identifier_start(c) || (c >= '0' && c <= '9'); }

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

bool is_group_function(const std::string& name) {
  return name == "count" || name == "mass" || name == "xcm" || name == "vcm" ||
         name == "fcm" || name == "bound" || name == "ke";
}

// Number of arguments of a math function; 0 when `name` is not one.
std::size_t math_function_arity(const std::string& name) {
  static const char* const kUnary[] = {"sqrt", "exp",  "ln",  "log",  "abs",  "sin",  "cos",
                                       "tan",  "asin", "acos", "atan", "ceil", "floor", "round"};
  for (const char* f : kUnary) {
    if (name == f) return 1;
  }
  if (name == "atan2" || name == "min" || name == "max") return 2;
  return 0;
}

// Applies a math function whose arguments are already checked against its domain.
double apply_math_function(const std::string& name, double x, double y) {
  if (name == "sqrt") return std::sqrt(x);
  if (name == "exp") return std::exp(x);
  if (name == "ln") return std::log(x);
  if (name == "log") return std::log10(x);
  if (name == "abs") return std::fabs(x);
  if (name == "sin") return std::sin(x);
  if (name == "cos") return std::cos(x);
  if (name == "tan") return std::tan(x);
  if (name == "asin") return std::asin(x);
  if (name == "acos") return std::acos(x);
  if (name == "atan") return std::atan(x);
  if (name == "ceil") return std::ceil(x);
  if (name == "floor") return std::floor(x);
  if (name == "round") return std::round(x);
  if (name == "atan2") return std::atan2(x, y);
  if (name == "min") return std::fmin(x, y);
  return std::fmax(x, y);  // "max"; callers pass only names known to math_function_arity
}

// Recursive-descent parser that evaluates while it parses.
class Parser {
 public:
  Parser(const std::string& formula, const Variables& vars, const EvalContext& ctx)
      : text_(formula), vars_(vars), ctx_(ctx) {}

  double parse_all() {
    skip_space();
    if (at_end()) fail("empty formula");
    const double value = parse_or();
    skip_space();
    if (!at_end()) fail("unexpected '" + rest_token() + "'");
    return value;
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const {
    // Long formulas are cut so that the error stays one readable line.
    constexpr std::size_t kShown = 200;
    const std::string shown =
        text_.size() > kShown ? text_.substr(0, kShown) + "..." : text_;
    throw EngineError(reason + " in formula '" + shown + "'");
  }

  bool at_end() const { return pos_ >= text_.size(); }
  char peek(std::size_t ahead = 0) const {
    return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
  }
  void skip_space() {
    while (!at_end() && is_space(text_[pos_])) ++pos_;
  }
  // Consumes `op` when it comes next (after blanks) and is not the start of a longer operator.
  bool accept(const char* op) {
    skip_space();
    std::size_t n = 0;
    while (op[n] != '\0') {
      if (peek(n) != op[n]) return false;
      ++n;
    }
    // '<' must not match the start of '<=', nor '!' the start of '!='.
    if (n == 1 && (op[0] == '<' || op[0] == '>' || op[0] == '!') && peek(1) == '=') return false;
    pos_ += n;
    return true;
  }
  void expect(char c) {
    skip_space();
    if (peek() != c) {
      if (at_end()) fail(std::string("missing '") + c + "' at end");
      fail(std::string("expected '") + c + "' before '" + rest_token() + "'");
    }
    ++pos_;
  }
  // The text from the current position up to the next blank, for messages.
  std::string rest_token() const {
    std::size_t end = pos_;
    while (end < text_.size() && !is_space(text_[end])) ++end;
    return text_.substr(pos_, end - pos_ == 0 ? 1 : end - pos_);
  }

  double parse_or() {
    double left = parse_and();
    while (accept("||")) {
      const double right = parse_and();
      left = (left != 0.0 || right != 0.0) ? 1.0 : 0.0;
    }
    return left;
  }
  double parse_and() {
    double left = parse_equality();
    while (accept("&&")) {
      const double right = parse_equality();
      left = (left != 0.0 && right != 0.0) ? 1.0 : 0.0;
    }
    return left;
  }
  double parse_equality() {
    double left = parse_relational();
    for (;;) {
      if (accept("==")) {
        left = left == parse_relational() ? 1.0 : 0.0;
      } else if (accept("!=")) {
        left = left != parse_relational() ? 1.0 : 0.0;
      } else {
        return left;
      }
    }
  }
  double parse_relational() {
    double left = parse_additive();
    for (;;) {
      if (accept("<=")) {
        left = left <= parse_additive() ? 1.0 : 0.0;
      } else if (accept(">=")) {
        left = left >= parse_additive() ? 1.0 : 0.0;
      } else if (accept("<")) {
        left = left < parse_additive() ? 1.0 : 0.0;
      } else if (accept(">")) {
        left = left > parse_additive() ? 1.0 : 0.0;
      } else {
        return left;
      }
    }
  }
  double parse_additive() {
    double left = parse_multiplicative();
    for (;;) {
      if (accept("+")) {
        left += parse_multiplicative();
      } else if (accept("-")) {
        left -= parse_multiplicative();
      } else {
        return left;
      }
    }
  }
  double parse_multiplicative() {
    double left = parse_power();
    for (;;) {
      if (accept("*")) {
        left *= parse_power();
      } else if (accept("/")) {
        const double right = parse_power();
        if (right == 0.0) fail("division by zero");
        left /= right;
      } else if (accept("%")) {
        const double right = parse_power();
        if (right == 0.0) fail("modulo by zero");
        left = std::fmod(left, right);
      } else {
        return left;
      }
    }
  }
  double parse_power() {
    // LAMMPS evaluates ^ left to right: a ^ b ^ c is (a ^ b) ^ c.
    double value = parse_unary();
    while (accept("^")) {
      const double exponent = parse_unary();
      if (value == 0.0 && exponent < 0.0) fail("zero raised to a negative power");
      if (value < 0.0 && exponent != std::floor(exponent)) {
        fail("negative number raised to a non-integer power");
      }
      value = std::pow(value, exponent);
    }
    return value;
  }
  double parse_unary() {
    const DepthGuard guard(nesting_depth, kMaxNesting);
    if (guard.exceeded()) fail("parentheses or unary operators nested too deeply");
    if (accept("-")) return -parse_unary();
    if (accept("!")) return parse_unary() == 0.0 ? 1.0 : 0.0;
    return parse_primary();
  }

  double parse_primary() {
    skip_space();
    if (at_end()) fail("formula ends where a value is expected");
    const char c = peek();
    if (c == '(') {
      ++pos_;
      const double value = parse_or();
      expect(')');
      return value;
    }
    if (is_digit(c) || c == '.') return parse_number();
    if (is_identifier_start(c)) return parse_name();
    fail("unexpected '" + rest_token() + "'");
  }

  double parse_number() {
    const std::size_t start = pos_;
    std::size_t digits = 0;
    while (is_digit(peek())) {
      ++pos_;
      ++digits;
    }
    if (peek() == '.') {
      ++pos_;
      while (is_digit(peek())) {
        ++pos_;
        ++digits;
      }
    }
    bool valid = digits > 0;
    if (valid && (peek() == 'e' || peek() == 'E')) {
      ++pos_;
      if (peek() == '+' || peek() == '-') ++pos_;
      if (!is_digit(peek())) valid = false;
      while (is_digit(peek())) ++pos_;
    }
    // A number glued to letters, digits or another '.' (1.2.3, 3abc, 2e) is one bad token.
    if (!valid || is_identifier_char(peek()) || peek() == '.') {
      while (is_identifier_char(peek()) || peek() == '.') ++pos_;
      fail("bad number '" + text_.substr(start, pos_ - start) + "'");
    }
    const std::string token = text_.substr(start, pos_ - start);
    errno = 0;
    const double value = std::strtod(token.c_str(), nullptr);
    if (errno == ERANGE && std::isinf(value)) fail("number '" + token + "' is out of range");
    return value;
  }

  std::string read_identifier() {
    const std::size_t start = pos_;
    while (is_identifier_char(peek())) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  double parse_name() {
    const std::string name = read_identifier();
    if (name.size() > 2 && name[1] == '_' && (name[0] == 'v' || name[0] == 'c' || name[0] == 'f')) {
      return parse_reference(name[0], name.substr(2));
    }
    skip_space();
    if (peek() == '(') {
      ++pos_;
      if (is_group_function(name)) return parse_group_function(name);
      const std::size_t arity = math_function_arity(name);
      if (arity == 0) fail("unknown function '" + name + "'");
      return parse_math_function(name, arity);
    }
    if (name == "PI") return kPi;
    std::optional<double> value;
    try {
      value = ctx_.thermo_keyword(name);
    } catch (const EngineError& e) {
      fail(e.what());
    }
    if (!value) fail("unknown name '" + name + "'");
    return *value;
  }

  double parse_reference(char kind, const std::string& id) {
    if (kind == 'v') {
      if (peek() == '[') fail("vector-style reference 'v_" + id + "[...]' is not supported");
      if (!vars_.exists(id)) fail("undefined variable 'v_" + id + "'");
      const DepthGuard guard(variable_depth, kMaxVariableDepth);
      if (guard.exceeded()) {
        fail("variable references nested deeper than " + std::to_string(kMaxVariableDepth) +
             " (circular reference?) at 'v_" + id + "'");
      }
      return vars_.number(id, ctx_);
    }
    int index = 0;
    if (peek() == '[') {
      ++pos_;
      const std::size_t start = pos_;
      while (is_digit(peek())) ++pos_;
      const std::string digits = text_.substr(start, pos_ - start);
      if (digits.empty() || peek() != ']' || digits.size() > 9 || std::stoi(digits) < 1) {
        fail(std::string("bad index in '") + kind + "_" + id +
             "[' (expected a positive integer and ']')");
      }
      ++pos_;
      index = std::stoi(digits);
    }
    try {
      return kind == 'c' ? ctx_.compute_value(id, index) : ctx_.fix_value(id, index);
    } catch (const EngineError& e) {
      fail(e.what());
    }
  }

  double parse_group_function(const std::string& name) {
    std::vector<std::string> args;
    for (;;) {
      skip_space();
      const std::string arg = read_identifier();
      skip_space();
      if (at_end()) fail("missing ')' after " + name + "(");
      if (arg.empty() || (peek() != ',' && peek() != ')')) {
        fail("group function " + name + "() takes a group ID and a keyword, not formulas");
      }
      args.push_back(arg);
      if (peek() == ')') {
        ++pos_;
        break;
      }
      ++pos_;
    }
    // count(g), mass(g), ke(g); xcm(g,dim), vcm(g,dim), fcm(g,dim), bound(g,dir); each
    // optionally with a trailing region ID (LAMMPS region functions).
    const bool with_keyword = name == "xcm" || name == "vcm" || name == "fcm" || name == "bound";
    const std::size_t wanted = with_keyword ? 2 : 1;
    if (args.size() != wanted && args.size() != wanted + 1) {
      fail(name + "() takes " + std::to_string(wanted) + " or " + std::to_string(wanted + 1) +
           " arguments, got " + std::to_string(args.size()));
    }
    if (name == "xcm" || name == "vcm" || name == "fcm") {
      if (args[1] != "x" && args[1] != "y" && args[1] != "z") {
        fail(name + "(): dimension must be x, y or z, not '" + args[1] + "'");
      }
    }
    if (name == "bound") {
      static const char* const kDirs[] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
      bool known = false;
      for (const char* dir : kDirs) known = known || args[1] == dir;
      if (!known) {
        fail("bound(): direction must be xmin|xmax|ymin|ymax|zmin|zmax, not '" + args[1] + "'");
      }
    }
    try {
      return ctx_.group_function(name, args);
    } catch (const EngineError& e) {
      fail(e.what());
    }
  }

  double parse_math_function(const std::string& name, std::size_t arity) {
    std::vector<double> args;
    skip_space();
    if (peek() != ')') {
      for (;;) {
        args.push_back(parse_or());
        if (!accept(",")) break;
      }
    }
    expect(')');
    if (args.size() != arity) {
      fail(name + "() takes " + std::to_string(arity) + " argument" + (arity == 1 ? "" : "s") +
           ", got " + std::to_string(args.size()));
    }
    const double x = args[0];
    const double y = arity == 2 ? args[1] : 0.0;
    if (name == "sqrt" && x < 0.0) fail("sqrt() of negative value");
    if ((name == "ln" || name == "log") && x <= 0.0) fail(name + "() of zero or negative value");
    if ((name == "asin" || name == "acos") && (x < -1.0 || x > 1.0)) {
      fail(name + "() of value outside [-1, 1]");
    }
    return apply_math_function(name, x, y);
  }

  const std::string& text_;
  const Variables& vars_;
  const EvalContext& ctx_;
  std::size_t pos_ = 0;
};

}  // namespace

double evaluate_expression(const std::string& formula, const Variables& vars,
                           const EvalContext& ctx) {
  Parser parser(formula, vars, ctx);
  return parser.parse_all();
}

}  // namespace dem

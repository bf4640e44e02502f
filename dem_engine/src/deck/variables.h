#pragma once
#include <map>
#include <string>
#include <vector>

#include "deck/eval_context.h"

namespace dem {

// Deck variables with LAMMPS/LIGGGHTS semantics for the styles index, loop, string and equal.
// Equal-style variables store their formula and are evaluated each time they are read.
class Variables {
 public:
  enum class Style { Index, Loop, String, Equal };

  // `variable NAME STYLE args...` (args are the command's words after "variable");
  // also `variable NAME delete`. Throws EngineError with a precise reason.
  void define(const std::vector<std::string>& args);
  // -var NAME VALUE ... on the command line: an index variable that a later
  // `variable NAME index ...` in the deck does not override (LAMMPS semantics).
  void define_from_command_line(const std::string& name, const std::vector<std::string>& values);
  bool exists(const std::string& name) const;
  Style style(const std::string& name) const;
  // Text that ${NAME} substitutes: current index/loop/string value, or the equal-style
  // formula evaluated and formatted with %.15g.
  std::string text(const std::string& name, const EvalContext& ctx) const;
  double number(const std::string& name, const EvalContext& ctx) const;
  // `next NAME...`: advances index/loop variables; returns false (and deletes them) when exhausted.
  bool next(const std::vector<std::string>& names);

 private:
  struct Entry {
    Style style = Style::String;
    std::vector<std::string> values;  // index values, or the single string/formula
    std::size_t position = 0;
    bool from_command_line = false;
    // Loop values are generated on demand: first + position, zero-padded to pad_width.
    long long loop_first = 0;
    std::size_t loop_count = 0;
    int pad_width = 0;
  };
  const Entry& entry(const std::string& name) const;
  std::map<std::string, Entry> entries_;
};

// Evaluates an equal-style formula: numbers, + - * / ^ %, unary -, !, comparisons, && ||,
// parentheses, math functions (sqrt exp ln log abs sin cos tan asin acos atan atan2 ceil floor
// round min max), PI, thermo keywords, group functions, c_ID / c_ID[i], f_ID / f_ID[i] and v_NAME.
// Throws EngineError naming the offending token.
double evaluate_expression(const std::string& formula, const Variables& vars, const EvalContext& ctx);

}  // namespace dem

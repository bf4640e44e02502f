#include "deck/variables.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "deck/errors.h"

namespace dem {

namespace {

bool is_valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_';
    if (!ok) return false;
  }
  return true;
}

void require_valid_name(const std::string& name) {
  if (!is_valid_name(name)) {
    throw EngineError("invalid variable name '" + name +
                      "' (only letters, digits and underscores are allowed)");
  }
}

const char* style_name(Variables::Style style) {
  switch (style) {
    case Variables::Style::Index:
      return "index";
    case Variables::Style::Loop:
      return "loop";
    case Variables::Style::String:
      return "string";
    case Variables::Style::Equal:
      return "equal";
  }
  return "unknown";
}

// Whole-word decimal integer (optional sign); anything else is rejected.
long long parse_loop_bound(const std::string& text, const std::string& variable) {
  const auto fail = [&]() -> long long {
    throw EngineError("loop variable '" + variable + "': '" + text + "' is not an integer");
  };
  if (text.empty()) return fail();
  std::size_t i = (text[0] == '-' || text[0] == '+') ? 1 : 0;
  if (i == text.size()) return fail();
  for (std::size_t k = i; k < text.size(); ++k) {
    if (text[k] < '0' || text[k] > '9') return fail();
  }
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (errno == ERANGE) return fail();
  return value;
}

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.15g", value);
  return buffer;
}

std::string loop_value(long long value, int pad_width) {
  std::string digits = std::to_string(value);
  if (pad_width > 0 && static_cast<int>(digits.size()) < pad_width && value >= 0) {
    digits.insert(0, static_cast<std::size_t>(pad_width) - digits.size(), '0');
  }
  return digits;
}

}  // namespace

void Variables::define(const std::vector<std::string>& args) {
  if (args.size() < 2) {
    throw EngineError("expected 'variable NAME STYLE ...' (got " + std::to_string(args.size()) +
                      " argument" + (args.size() == 1 ? "" : "s") + ")");
  }
  const std::string& name = args[0];
  const std::string& style = args[1];
  require_valid_name(name);
  const std::vector<std::string> values(args.begin() + 2, args.end());
  const auto existing = entries_.find(name);

  if (style == "delete") {
    if (!values.empty()) throw EngineError("'variable " + name + " delete' takes no values");
    entries_.erase(name);
    return;
  }
  if (style == "index") {
    if (values.empty()) throw EngineError("index variable '" + name + "' needs at least one value");
    // LAMMPS: an existing variable of this name (e.g. from -var) is kept unchanged.
    if (existing != entries_.end()) return;
    Entry entry;
    entry.style = Style::Index;
    entry.values = values;
    entries_[name] = entry;
    return;
  }
  if (style == "loop") {
    std::vector<std::string> bounds = values;
    bool pad = false;
    if (!bounds.empty() && bounds.back() == "pad") {
      pad = true;
      bounds.pop_back();
    }
    if (bounds.empty() || bounds.size() > 2) {
      throw EngineError("loop variable '" + name +
                        "' expects 'loop N [pad]' or 'loop N1 N2 [pad]'");
    }
    long long first = 1;
    long long last = 0;
    if (bounds.size() == 1) {
      last = parse_loop_bound(bounds[0], name);
      if (last < 1) throw EngineError("loop variable '" + name + "': N must be at least 1");
    } else {
      first = parse_loop_bound(bounds[0], name);
      last = parse_loop_bound(bounds[1], name);
      if (first < 0 || last < first) {
        throw EngineError("loop variable '" + name + "': need 0 <= N1 <= N2, got " + bounds[0] +
                          " " + bounds[1]);
      }
    }
    if (existing != entries_.end()) return;
    Entry entry;
    entry.style = Style::Loop;
    entry.loop_first = first;
    entry.loop_count = static_cast<std::size_t>(last - first) + 1;
    entry.pad_width = pad ? static_cast<int>(std::to_string(last).size()) : 0;
    entries_[name] = entry;
    return;
  }
  if (style == "string" || style == "equal") {
    const Style wanted = style == "string" ? Style::String : Style::Equal;
    if (values.size() != 1) {
      throw EngineError(style + " variable '" + name +
                        "' takes exactly one word (quote text that contains spaces), got " +
                        std::to_string(values.size()));
    }
    if (existing != entries_.end() && existing->second.style != wanted) {
      std::string reason = "cannot redefine " + std::string(style_name(existing->second.style)) +
                           " variable '" + name + "' as " + style + " style";
      if (existing->second.from_command_line) reason += " (it was set with -var)";
      throw EngineError(reason);
    }
    Entry entry;
    entry.style = wanted;
    entry.values = values;
    entries_[name] = entry;
    return;
  }
  throw EngineError("variable style '" + style + "' of '" + name +
                    "' is not supported (use index, loop, string, equal or delete)");
}

void Variables::define_from_command_line(const std::string& name,
                                         const std::vector<std::string>& values) {
  require_valid_name(name);
  if (values.empty()) throw EngineError("-var " + name + " needs at least one value");
  Entry entry;
  entry.style = Style::Index;
  entry.values = values;
  entry.from_command_line = true;
  entries_[name] = entry;
}

bool Variables::exists(const std::string& name) const { return entries_.count(name) != 0; }

Variables::Style Variables::style(const std::string& name) const { return entry(name).style; }

const Variables::Entry& Variables::entry(const std::string& name) const {
  const auto found = entries_.find(name);
  if (found == entries_.end()) throw EngineError("undefined variable '" + name + "'");
  return found->second;
}

std::string Variables::text(const std::string& name, const EvalContext& ctx) const {
  const Entry& e = entry(name);
  switch (e.style) {
    case Style::Index:
      return e.values[e.position];
    case Style::Loop:
      return loop_value(e.loop_first + static_cast<long long>(e.position), e.pad_width);
    case Style::String:
      return e.values[0];
    case Style::Equal:
      return format_number(evaluate_expression(e.values[0], *this, ctx));
  }
  throw EngineError("variable '" + name + "' has an unknown style");
}

double Variables::number(const std::string& name, const EvalContext& ctx) const {
  const Entry& e = entry(name);
  if (e.style == Style::Equal) return evaluate_expression(e.values[0], *this, ctx);
  const std::string value = text(name, ctx);
  const char* begin = value.c_str();
  char* end = nullptr;
  errno = 0;
  const double result = std::strtod(begin, &end);
  // The whole value must be one finite number; strtod alone would accept "3abc" as 3.
  const bool whole = end != begin && *end == '\0';
  if (!whole || errno == ERANGE || !std::isfinite(result)) {
    throw EngineError(std::string(style_name(e.style)) + " variable '" + name + "' value '" +
                      value + "' is not a number");
  }
  return result;
}

bool Variables::next(const std::vector<std::string>& names) {
  if (names.empty()) throw EngineError("expected at least one variable name");
  const Style first_style = entry(names[0]).style;
  for (const std::string& name : names) {
    const Style s = entry(name).style;
    if (s != Style::Index && s != Style::Loop) {
      throw EngineError("variable '" + name + "' is " + style_name(s) +
                        " style; only index and loop variables can be advanced");
    }
    if (s != first_style) {
      throw EngineError("all variables advanced together must have the same style ('" + name +
                        "' is " + style_name(s) + ", '" + names[0] + "' is " +
                        style_name(first_style) + ")");
    }
  }
  // LAMMPS semantics: each variable advances; exhausted ones are deleted.
  bool all_remaining = true;
  for (const std::string& name : names) {
    const auto found = entries_.find(name);
    if (found == entries_.end()) continue;  // listed twice and already deleted
    Entry& e = found->second;
    ++e.position;
    const std::size_t count = e.style == Style::Loop ? e.loop_count : e.values.size();
    if (e.position >= count) {
      entries_.erase(found);
      all_remaining = false;
    }
  }
  return all_remaining;
}

}  // namespace dem

#include "deck/input.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "deck/line_lexer_internal.h"

namespace dem {

// ---------------------------------------------------------------------------------------------
// Line text rules (declared in line_lexer_internal.h)
// ---------------------------------------------------------------------------------------------
namespace deck_lexer {

namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

bool starts_triple(const std::string& text, std::size_t i) {
  return text.compare(i, 3, R"(""")") == 0;
}

enum class Quote { None, Single, Double, Triple };

// Which characters lie inside quotes (quote characters included) and where a '#' comment
// starts, following the word-start rule for opening quotes.
struct QuoteScan {
  std::vector<bool> quoted;
  std::size_t comment = std::string::npos;
  Quote open_at_end = Quote::None;
};

QuoteScan scan_quotes(const std::string& text) {
  QuoteScan scan;
  scan.quoted.assign(text.size(), false);
  Quote state = Quote::None;
  bool word_start = true;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (state == Quote::None) {
      if (c == '#') {
        scan.comment = i;
        break;
      }
      if (is_blank(c)) {
        word_start = true;
        ++i;
        continue;
      }
      if (word_start && starts_triple(text, i)) {
        state = Quote::Triple;
        scan.quoted[i] = scan.quoted[i + 1] = scan.quoted[i + 2] = true;
        i += 3;
      } else if (word_start && (c == '"' || c == '\'')) {
        state = c == '"' ? Quote::Double : Quote::Single;
        scan.quoted[i] = true;
        ++i;
      } else {
        ++i;
      }
      word_start = false;
      continue;
    }
    scan.quoted[i] = true;
    if (state == Quote::Triple && starts_triple(text, i)) {
      scan.quoted[i + 1] = scan.quoted[i + 2] = true;
      i += 3;
      state = Quote::None;
      continue;
    }
    if ((state == Quote::Double && c == '"') || (state == Quote::Single && c == '\'')) {
      state = Quote::None;
    }
    ++i;
  }
  scan.open_at_end = state;
  return scan;
}

// Snippet of `text` from `from` for messages, cut at a sensible length.
std::string excerpt(const std::string& text, std::size_t from) {
  constexpr std::size_t kMax = 40;
  std::string part = text.substr(from, kMax);
  for (char& c : part) {
    if (c == '\n') c = ' ';
  }
  if (text.size() - from > kMax) part += "...";
  return part;
}

// Checks one conversion %[flags][width][.precision]conv starting at format[i] == '%';
// returns the index after it.
std::size_t check_conversion(const std::string& format, std::size_t i) {
  const auto bad = [&]() -> std::size_t {
    throw EngineError("format '" + format +
                      "' must hold one floating-point conversion such as %.6g, %10.4f or %e");
  };
  ++i;
  while (i < format.size() && std::string("-+ #0").find(format[i]) != std::string::npos) ++i;
  std::size_t digits = 0;
  while (i < format.size() && format[i] >= '0' && format[i] <= '9') {
    ++i;
    ++digits;
  }
  if (digits > 3) return bad();
  if (i < format.size() && format[i] == '.') {
    ++i;
    digits = 0;
    while (i < format.size() && format[i] >= '0' && format[i] <= '9') {
      ++i;
      ++digits;
    }
    if (digits > 3) return bad();
  }
  if (i >= format.size() || std::string("eEfFgG").find(format[i]) == std::string::npos) {
    return bad();
  }
  return i + 1;
}

}  // namespace

bool ends_inside_triple_quote(const std::string& text) {
  return scan_quotes(text).open_at_end == Quote::Triple;
}

std::string strip_comment(const std::string& text) {
  const QuoteScan scan = scan_quotes(text);
  return scan.comment == std::string::npos ? text : text.substr(0, scan.comment);
}

std::vector<Word> split_words(const std::string& text) {
  std::vector<Word> words;
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (true) {
    while (i < n && is_blank(text[i])) ++i;
    if (i >= n) break;
    Word word;
    if (starts_triple(text, i) || text[i] == '"' || text[i] == '\'') {
      const std::string quote = starts_triple(text, i) ? R"(""")" : std::string(1, text[i]);
      const std::size_t close = text.find(quote, i + quote.size());
      if (close == std::string::npos) {
        throw EngineError("unterminated quote " + quote + " in: " + excerpt(text, i));
      }
      word.text = text.substr(i + quote.size(), close - i - quote.size());
      word.quoted = true;
      i = close + quote.size();
      if (i < n && !is_blank(text[i])) {
        throw EngineError("text directly after a closing quote " + quote + " in: " +
                          excerpt(text, i) + " (a quoted word must end at a blank)");
      }
    } else {
      const std::size_t start = i;
      while (i < n && !is_blank(text[i])) ++i;
      word.text = text.substr(start, i - start);
    }
    words.push_back(std::move(word));
  }
  return words;
}

std::string substitute_references(const std::string& text, bool skip_quoted,
                                  const VariableLookup& variable,
                                  const ImmediateLookup& immediate) {
  std::vector<bool> quoted;
  if (skip_quoted) quoted = scan_quotes(text).quoted;
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c != '$' || (skip_quoted && quoted[i])) {
      out += c;
      ++i;
      continue;
    }
    if (i + 1 >= text.size()) {
      throw EngineError("'$' at end of line (write $x, ${name} or $(formula))");
    }
    const char next = text[i + 1];
    if (next == '{') {
      const std::size_t close = text.find('}', i + 2);
      if (close == std::string::npos) {
        throw EngineError("missing '}' in variable reference " + excerpt(text, i));
      }
      const std::string name = text.substr(i + 2, close - i - 2);
      if (name.empty()) throw EngineError("empty variable name in '${}'");
      out += variable(name);
      i = close + 1;
    } else if (next == '(') {
      int depth = 0;
      std::size_t close = std::string::npos;
      for (std::size_t k = i + 1; k < text.size(); ++k) {
        if (text[k] == '(') ++depth;
        if (text[k] == ')' && --depth == 0) {
          close = k;
          break;
        }
      }
      if (close == std::string::npos) {
        throw EngineError("missing ')' in immediate formula " + excerpt(text, i));
      }
      const std::string inner = text.substr(i + 2, close - i - 2);
      const std::size_t colon = inner.rfind(':');
      if (colon != std::string::npos && colon + 1 < inner.size() && inner[colon + 1] == '%') {
        out += immediate(inner.substr(0, colon), inner.substr(colon + 1));
      } else {
        out += immediate(inner, "");
      }
      i = close + 1;
    } else if (is_blank(next)) {
      throw EngineError("'$' followed by a blank (write $x, ${name} or $(formula))");
    } else {
      out += variable(std::string(1, next));
      i += 2;
    }
  }
  return out;
}

std::string format_number(const std::string& format, double value) {
  std::size_t conversions = 0;
  for (std::size_t i = 0; i < format.size();) {
    if (format[i] != '%') {
      ++i;
    } else if (i + 1 < format.size() && format[i + 1] == '%') {
      i += 2;
    } else {
      i = check_conversion(format, i);
      ++conversions;
    }
  }
  if (conversions != 1) {
    throw EngineError("format '" + format + "' must hold exactly one conversion such as %.6g");
  }
  // The format is validated above to take exactly one double.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#endif
  const int length = std::snprintf(nullptr, 0, format.c_str(), value);
  if (length < 0) throw EngineError("cannot format a number with '" + format + "'");
  std::string out(static_cast<std::size_t>(length) + 1, '\0');
  std::snprintf(out.data(), out.size(), format.c_str(), value);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  out.resize(static_cast<std::size_t>(length));
  return out;
}

std::string first_word(const std::string& text) {
  std::size_t start = 0;
  while (start < text.size() && is_blank(text[start])) ++start;
  std::size_t end = start;
  while (end < text.size() && !is_blank(text[end])) ++end;
  return text.substr(start, end - start);
}

}  // namespace deck_lexer

// ---------------------------------------------------------------------------------------------
// Input
// ---------------------------------------------------------------------------------------------

struct Input::FileReader {
  std::string path;
  std::vector<std::string> lines;  // physical lines without line terminators
  std::size_t next = 0;            // index of the next physical line to read
  bool scanning = false;           // skipping lines up to `label <label>` after a jump
  std::string label;
  SourceLocation jump_where;
};

namespace {

// Include files nested deeper than this are taken as an include cycle.
constexpr int kMaxIncludeDepth = 32;

// Sets `target` to `value` for the lifetime of the guard, then restores the old value.
template <typename T>
class ScopedValue {
 public:
  ScopedValue(T& target, T value) : target_(target), saved_(std::move(target)) {
    target_ = std::move(value);
  }
  ~ScopedValue() { target_ = std::move(saved_); }
  ScopedValue(const ScopedValue&) = delete;
  ScopedValue& operator=(const ScopedValue&) = delete;

 private:
  T& target_;
  T saved_;
};

// Physical lines of a deck file ('\r' of CRLF endings removed); false when it cannot be read.
bool read_physical_lines(const std::string& path, std::vector<std::string>& lines) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return !in.bad();
}

// Joins the physical lines of one command starting at lines[index] and advances index past
// them: a trailing '&' is removed and the next line appended directly (LAMMPS rule); a line
// ending inside """...""" continues after a newline.
std::string assemble_logical_line(const std::vector<std::string>& lines, std::size_t& index) {
  std::string text = lines[index++];
  for (;;) {
    const std::size_t last = text.find_last_not_of(" \t\r\f\v");
    if (last != std::string::npos && text[last] == '&') {
      if (index >= lines.size()) throw EngineError("line continuation '&' at end of file");
      text.erase(last);
      text += lines[index++];
      continue;
    }
    if (deck_lexer::ends_inside_triple_quote(text)) {
      if (index >= lines.size()) {
        throw EngineError(R"(unterminated triple quote """ at end of file)");
      }
      text += '\n';
      text += lines[index++];
      continue;
    }
    return text;
  }
}

// True when `line` is `label NAME`; lines that do not parse are simply not labels.
bool is_label_line(const std::string& line, const std::string& label) {
  try {
    const std::vector<deck_lexer::Word> words =
        deck_lexer::split_words(deck_lexer::strip_comment(line));
    return words.size() == 2 && words[0].text == "label" && words[1].text == label;
  } catch (const EngineError&) {
    return false;
  }
}

std::string substitute_text(const std::string& text, bool skip_quoted, const Variables& variables,
                            const EvalContext& ctx) {
  return deck_lexer::substitute_references(
      text, skip_quoted, [&](const std::string& name) { return variables.text(name, ctx); },
      [&](const std::string& formula, const std::string& format) {
        const double value = evaluate_expression(formula, variables, ctx);
        return deck_lexer::format_number(format.empty() ? "%.15g" : format, value);
      });
}

}  // namespace

Input::Input(CommandHandler& handler, Variables& variables)
    : handler_(handler), variables_(variables) {}

void Input::run_file(const std::string& path) {
  FileReader reader;
  reader.path = path;
  if (!read_physical_lines(path, reader.lines)) {
    throw DeckError(SourceLocation{path, 0}, "", "cannot open deck file '" + path + "'");
  }
  run_reader(reader);
}

void Input::run_reader(FileReader& reader) {
  const ScopedValue<FileReader*> reading(reader_, &reader);
  const ScopedValue<int> depth(include_depth_, include_depth_ + 1);
  while (reader.next < reader.lines.size()) {
    const SourceLocation where{reader.path, static_cast<int>(reader.next) + 1};
    std::string line;
    try {
      line = assemble_logical_line(reader.lines, reader.next);
    } catch (const EngineError& e) {
      const std::string& first = reader.lines[static_cast<std::size_t>(where.line) - 1];
      throw DeckError(where, deck_lexer::first_word(deck_lexer::strip_comment(first)), e.what());
    }
    if (reader.scanning) {
      if (is_label_line(line, reader.label)) reader.scanning = false;
      continue;
    }
    execute_line(line, where);
  }
  if (reader.scanning) {
    throw DeckError(reader.jump_where, "jump",
                    "label '" + reader.label + "' not found in '" + reader.path + "'");
  }
}

void Input::run_line(const std::string& text, const SourceLocation& where) {
  // A single line has no file to jump in; the caller's location is restored afterwards.
  const ScopedValue<FileReader*> no_reader(reader_, nullptr);
  const ScopedValue<SourceLocation> location(current_, current_);
  execute_line(text, where);
}

std::string Input::substitute(const std::string& text) const {
  return substitute_text(text, false, variables_, handler_.eval_context());
}

void Input::execute_line(const std::string& line, const SourceLocation& where) {
  current_ = where;
  std::string name;
  try {
    if (echo_) handler_.message(line);
    const std::string text = deck_lexer::strip_comment(line);
    name = deck_lexer::first_word(text);
    // Line-level substitution leaves quoted words alone (LAMMPS parsing rule).
    const std::string substituted =
        substitute_text(text, true, variables_, handler_.eval_context());
    const std::vector<deck_lexer::Word> words = deck_lexer::split_words(substituted);
    if (words.empty()) return;
    Command command;
    command.where = where;
    command.name = words[0].text;
    name = command.name;
    for (std::size_t i = 1; i < words.size(); ++i) command.args.push_back(words[i].text);
    const bool first_arg_quoted = words.size() > 1 && words[1].quoted;
    dispatch(command, first_arg_quoted);
  } catch (const DeckError&) {
    throw;  // already located, e.g. inside an include file
  } catch (const std::bad_alloc&) {
    throw DeckError(where, name, "out of memory (is a count or size in this command too large?)");
  } catch (const std::exception& e) {
    throw DeckError(where, name, e.what());
  } catch (...) {
    throw DeckError(where, name, "unknown error");
  }
}

void Input::dispatch(const Command& command, bool text_quoted) {
  const std::string& name = command.name;
  const std::vector<std::string>& args = command.args;
  if (name == "variable") {
    variables_.define(args);
  } else if (name == "next") {
    if (!variables_.next(args)) jump_skip_ = true;
  } else if (name == "print") {
    run_print(command, text_quoted);
  } else if (name == "include") {
    run_include(command);
  } else if (name == "log") {
    if (args.empty() || args.size() > 2 || (args.size() == 2 && args[1] != "append")) {
      throw EngineError("expected 'log FILE [append]'");
    }
    handler_.open_log(args[0], args.size() == 2);
  } else if (name == "echo") {
    if (args.size() != 1) throw EngineError("expected 'echo none|screen|log|both'");
    if (args[0] == "none") {
      echo_ = false;
    } else if (args[0] == "screen" || args[0] == "log" || args[0] == "both") {
      echo_ = true;
    } else {
      throw EngineError("echo mode must be none, screen, log or both, not '" + args[0] + "'");
    }
  } else if (name == "label") {
    if (args.size() != 1) throw EngineError("expected 'label NAME'");
  } else if (name == "jump") {
    run_jump(command);
  } else if (name == "if") {
    run_if(command, text_quoted);
  } else if (name == "shell") {
    throw EngineError("shell commands are refused: a deck may not run programs on the host");
  } else {
    handler_.execute(command);
  }
}

void Input::run_print(const Command& command, bool text_quoted) {
  const std::vector<std::string>& args = command.args;
  if (args.empty()) {
    throw EngineError("expected 'print TEXT [file F] [append F] [screen yes|no]'");
  }
  // Quoted text was skipped by line substitution; print substitutes it now (LAMMPS rule).
  const std::string text = text_quoted ? substitute(args[0]) : args[0];
  std::string path;
  bool append = false;
  bool screen = true;
  for (std::size_t i = 1; i < args.size(); i += 2) {
    const std::string& key = args[i];
    if (key != "file" && key != "append" && key != "screen") {
      throw EngineError("unknown keyword '" + key +
                        "' (print takes one TEXT word: quote text that contains spaces)");
    }
    if (i + 1 >= args.size()) throw EngineError("missing value after '" + key + "'");
    const std::string& value = args[i + 1];
    if (key == "screen") {
      if (value != "yes" && value != "no") {
        throw EngineError("screen must be yes or no, not '" + value + "'");
      }
      screen = value == "yes";
    } else {
      path = value;
      append = key == "append";
    }
  }
  if (screen) handler_.message(text);
  if (!path.empty()) {
    std::ofstream out(path, append ? std::ios::app : std::ios::trunc);
    if (!out) throw EngineError("cannot open '" + path + "' for writing");
    out << text << '\n';
    if (!out) throw EngineError("cannot write to '" + path + "'");
  }
}

// if "COND" then "CMD" ... [elif "COND" "CMD" ...] ... [else "CMD" ...] (LAMMPS semantics):
// the first true branch runs its commands, each as a deck line at the `if` line, so that a
// `jump SELF label` among them continues a loop in the current file.
void Input::run_if(const Command& command, bool condition_quoted) {
  const std::vector<std::string>& a = command.args;
  if (a.size() < 3 || a[1] != "then") {
    throw EngineError("expected 'if \"CONDITION\" then \"COMMAND\" ... [elif ...] [else ...]'");
  }
  auto holds = [&](const std::string& condition, bool quoted) {
    const std::string text = quoted ? substitute(condition) : condition;
    return evaluate_expression(text, variables_, handler_.eval_context()) != 0.0;
  };
  std::size_t i = 2;
  bool taken = holds(a[0], condition_quoted);
  bool done = false;
  while (i < a.size()) {
    std::vector<std::string> commands;
    while (i < a.size() && a[i] != "elif" && a[i] != "else") commands.push_back(a[i++]);
    if (commands.empty()) throw EngineError("if: a branch has no command");
    if (taken && !done) {
      for (const std::string& line : commands) execute_line(line, command.where);
      done = true;
    }
    if (i >= a.size()) break;
    if (a[i] == "else") {
      ++i;
      taken = true;
      if (i >= a.size()) throw EngineError("if: 'else' has no command");
      std::vector<std::string> rest(a.begin() + static_cast<long>(i), a.end());
      for (const std::string& w : rest)
        if (w == "elif" || w == "else") throw EngineError("if: nothing may follow the else branch");
      if (!done)
        for (const std::string& line : rest) execute_line(line, command.where);
      return;
    }
    // elif: the condition word was not substituted on the line only if it was quoted; it is
    // substituted here in either case (substitution of plain text is idempotent).
    if (i + 1 >= a.size()) throw EngineError("if: 'elif' needs a condition and commands");
    taken = !done && holds(a[i + 1], true);
    i += 2;
  }
}

void Input::run_include(const Command& command) {
  if (command.args.size() != 1) throw EngineError("expected 'include FILE'");
  if (include_depth_ >= kMaxIncludeDepth) {
    throw EngineError("include files nested deeper than " + std::to_string(kMaxIncludeDepth) +
                      " (does a file include itself?)");
  }
  FileReader reader;
  reader.path = command.args[0];
  // Relative paths resolve against the working directory, as in LAMMPS.
  if (!read_physical_lines(reader.path, reader.lines)) {
    throw EngineError("cannot open file '" + reader.path + "'");
  }
  run_reader(reader);
}

void Input::run_jump(const Command& command) {
  const std::vector<std::string>& args = command.args;
  if (args.empty() || args.size() > 2) throw EngineError("expected 'jump SELF [LABEL]'");
  if (jump_skip_) {  // a `next` ran out of values: this jump ends the loop
    jump_skip_ = false;
    return;
  }
  if (args[0] != "SELF") {
    throw EngineError("only 'jump SELF [LABEL]' is supported, not a jump to '" + args[0] + "'");
  }
  if (reader_ == nullptr) throw EngineError("jump is only allowed in a deck file");
  reader_->next = 0;
  reader_->scanning = args.size() == 2;
  reader_->label = args.size() == 2 ? args[1] : std::string();
  reader_->jump_where = command.where;
}

}  // namespace dem

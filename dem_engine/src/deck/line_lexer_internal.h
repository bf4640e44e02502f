#pragma once
// Text rules of deck lines (LAMMPS parsing rules), kept apart from command execution.
// A quote opens a quoted word only at the start of a word: ' and " run to the same quote
// character, """ to the next """ (and may span lines). Quote characters inside a word are
// ordinary characters.
#include <functional>
#include <string>
#include <vector>

namespace dem::deck_lexer {

struct Word {
  std::string text;     // the word with its enclosing quotes removed
  bool quoted = false;  // the word was written in quotes
};

// True when `text` ends inside a """...""" word, so the next physical line belongs to it.
bool ends_inside_triple_quote(const std::string& text);

// `text` up to its first '#' that is not inside quotes.
std::string strip_comment(const std::string& text);

// Splits comment-free text into words. Throws EngineError for an unterminated quote or for
// text glued to a closing quote.
std::vector<Word> split_words(const std::string& text);

// Value of ${name} or $x.
using VariableLookup = std::function<std::string(const std::string& name)>;
// Value of $(expression) or $(expression:format); format is "" when not given.
using ImmediateLookup =
    std::function<std::string(const std::string& expression, const std::string& format)>;

// Replaces $x, ${name} and $(expression[:format]) in one pass; substituted text is not scanned
// again. With skip_quoted, references inside quoted words stay as written. Throws EngineError
// for a malformed reference (and passes on what the lookups throw).
std::string substitute_references(const std::string& text, bool skip_quoted,
                                  const VariableLookup& variable, const ImmediateLookup& immediate);

// `value` printed with a printf format that holds exactly one floating-point conversion
// (%[flags][width][.precision] e|E|f|F|g|G) plus optional literal text and %% escapes.
// Throws EngineError for any other format.
std::string format_number(const std::string& format, double value);

// First blank-separated word of `text` ("" when blank), used to name a command in messages.
std::string first_word(const std::string& text);

}  // namespace dem::deck_lexer

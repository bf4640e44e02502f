#pragma once
#include <string>
#include <vector>

#include "deck/command.h"
#include "deck/errors.h"
#include "deck/variables.h"

namespace dem {

// Receives every command the input reader does not handle itself.
class CommandHandler {
 public:
  virtual ~CommandHandler() = default;
  // Executes one command; throws EngineError (or DeckError) on bad arguments.
  virtual void execute(const Command& command) = 0;
  // Text for the screen and the log file (print, messages).
  virtual void message(const std::string& text) = 0;
  // `log FILE [append]`.
  virtual void open_log(const std::string& path, bool append) = 0;
  virtual const EvalContext& eval_context() const = 0;
};

// Reads decks: comments, '&' continuation, quotes, variable substitution (${name}, $x, $(expr)),
// and the built-in commands variable, next, print, include, log, echo, label, jump, if and
// shell (refused). Every error leaves as a DeckError carrying the file and line of the command.
class Input {
 public:
  Input(CommandHandler& handler, Variables& variables);
  void run_file(const std::string& path);
  // Executes one command line (no continuation), e.g. from `run N every M "command"`.
  void run_line(const std::string& text, const SourceLocation& where);
  // Substitutes variables in text (used by print and fix print at output time).
  std::string substitute(const std::string& text) const;
  const SourceLocation& current() const noexcept { return current_; }

 private:
  struct FileReader;  // physical lines of one deck file and the read position (input.cpp)
  void run_reader(FileReader& reader);
  void execute_line(const std::string& line, const SourceLocation& where);
  void run_if(const Command& command, bool condition_quoted);
  void dispatch(const Command& command, bool text_quoted);
  void run_print(const Command& command, bool text_quoted);
  void run_include(const Command& command);
  void run_jump(const Command& command);
  CommandHandler& handler_;
  Variables& variables_;
  SourceLocation current_;
  int include_depth_ = 0;
  bool echo_ = false;
  // Set when `next` exhausts a variable: the following `jump` is skipped (ends a loop).
  bool jump_skip_ = false;
  // Innermost deck file being read (non-owning; the reader lives in run_reader's caller).
  FileReader* reader_ = nullptr;
};

}  // namespace dem

#include "deck/errors.h"

#include <utility>

namespace dem {

namespace {

// "FILE:LINE: command: reason"; the line is left out when unknown (0) and the command when
// the error precedes word splitting of a line that has no name yet.
std::string format_deck_error(const SourceLocation& where, const std::string& command,
                              const std::string& reason) {
  std::string text = where.file;
  if (where.line > 0) text += ":" + std::to_string(where.line);
  text += ": ";
  if (!command.empty()) text += command + ": ";
  text += reason;
  return text;
}

}  // namespace

DeckError::DeckError(SourceLocation where, std::string command, std::string reason)
    : std::runtime_error(format_deck_error(where, command, reason)),
      where_(std::move(where)),
      command_(std::move(command)),
      reason_(std::move(reason)) {}

}  // namespace dem

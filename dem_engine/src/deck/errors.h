#pragma once
#include <stdexcept>
#include <string>

#include "deck/source_location.h"

namespace dem {

// Raised by command handlers and physics code that do not know the deck location;
// the input reader attaches the location of the command being executed.
class EngineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An error with its deck location; what() is "FILE:LINE: command: reason".
class DeckError : public std::runtime_error {
 public:
  DeckError(SourceLocation where, std::string command, std::string reason);
  const SourceLocation& where() const noexcept { return where_; }
  const std::string& command() const noexcept { return command_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  SourceLocation where_;
  std::string command_;
  std::string reason_;
};

}  // namespace dem

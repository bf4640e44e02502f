#include "core/groups.h"

#include "deck/errors.h"

namespace dem {

bool Groups::exists(const std::string& name) const {
  for (const auto& n : names_)
    if (n == name) return true;
  return false;
}

std::uint32_t Groups::bit(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return 1u << i;
  throw EngineError("unknown group '" + name + "'");
}

std::uint32_t Groups::find_or_create(const std::string& name) {
  if (exists(name)) return bit(name);
  if (names_.size() >= 32) throw EngineError("too many groups (at most 32)");
  names_.push_back(name);
  return 1u << (names_.size() - 1);
}

}  // namespace dem

#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace dem {

// Named particle groups as bits of a 32-bit mask; "all" is bit 0 and always exists.
class Groups {
 public:
  Groups() { names_.push_back("all"); }
  // Bit of an existing group; throws EngineError naming the group if unknown.
  std::uint32_t bit(const std::string& name) const;
  bool exists(const std::string& name) const;
  // Bit of the group, created if new; throws when all 32 groups are used.
  std::uint32_t find_or_create(const std::string& name);

 private:
  std::vector<std::string> names_;
};

}  // namespace dem

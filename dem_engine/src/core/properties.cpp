#include "core/properties.h"

#include "deck/errors.h"

namespace dem {

void PropertyStore::set(const std::string& name, GlobalProperty value, const std::string& owner) {
  props_[name] = std::move(value);
  owner_[name] = owner;
}

void PropertyStore::remove_owned_by(const std::string& owner) {
  for (auto it = owner_.begin(); it != owner_.end();) {
    if (it->second == owner) {
      props_.erase(it->first);
      it = owner_.erase(it);
    } else {
      ++it;
    }
  }
}

const GlobalProperty& PropertyStore::get(const std::string& name) const {
  auto it = props_.find(name);
  if (it == props_.end())
    throw EngineError("material property '" + name +
                      "' is not defined (fix property/global " + name + " ...)");
  return it->second;
}

}  // namespace dem

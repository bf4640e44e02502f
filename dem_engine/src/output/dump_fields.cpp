#include "output/dump_fields.h"

#include <map>

#include "deck/errors.h"

namespace dem {

std::vector<DumpField> parse_dump_fields(const std::vector<std::string>& words) {
  using K = DumpField::Kind;
  static const std::map<std::string, K> kinds = {
      {"id", K::Id},         {"type", K::Type},     {"x", K::X},
      {"y", K::Y},           {"z", K::Z},           {"vx", K::Vx},
      {"vy", K::Vy},         {"vz", K::Vz},         {"fx", K::Fx},
      {"fy", K::Fy},         {"fz", K::Fz},         {"omegax", K::OmegaX},
      {"omegay", K::OmegaY}, {"omegaz", K::OmegaZ}, {"tqx", K::TqX},
      {"tqy", K::TqY},       {"tqz", K::TqZ},       {"radius", K::Radius},
      {"diameter", K::Diameter}, {"mass", K::Mass}, {"density", K::Density}};
  std::vector<DumpField> fields;
  for (const std::string& word : words) {
    DumpField field;
    field.name = word;
    if (auto it = kinds.find(word); it != kinds.end()) {
      field.kind = it->second;
    } else if (word.rfind("c_", 0) == 0 && word.size() > 2) {
      if (word.find('[') != std::string::npos)
        throw EngineError("dump field '" + word +
                          "': per-atom compute arrays are not supported (use c_ID)");
      field.kind = K::Compute;
      field.compute_id = word.substr(2);
    } else {
      throw EngineError("unknown or unsupported dump field '" + word + "'");
    }
    fields.push_back(field);
  }
  if (fields.empty()) throw EngineError("dump needs at least one field");
  return fields;
}

double dump_field_value(const DumpField& field, const Particles& atoms, std::size_t i,
                        const std::vector<double>& compute_values) {
  using K = DumpField::Kind;
  switch (field.kind) {
    case K::Id: return static_cast<double>(atoms.tag[i]);
    case K::Type: return atoms.type[i];
    case K::X: return atoms.x[i].x;
    case K::Y: return atoms.x[i].y;
    case K::Z: return atoms.x[i].z;
    case K::Vx: return atoms.v[i].x;
    case K::Vy: return atoms.v[i].y;
    case K::Vz: return atoms.v[i].z;
    case K::Fx: return atoms.f[i].x;
    case K::Fy: return atoms.f[i].y;
    case K::Fz: return atoms.f[i].z;
    case K::OmegaX: return atoms.omega[i].x;
    case K::OmegaY: return atoms.omega[i].y;
    case K::OmegaZ: return atoms.omega[i].z;
    case K::TqX: return atoms.torque[i].x;
    case K::TqY: return atoms.torque[i].y;
    case K::TqZ: return atoms.torque[i].z;
    case K::Radius: return atoms.radius[i];
    case K::Diameter: return 2.0 * atoms.radius[i];
    case K::Mass: return atoms.rmass[i];
    case K::Density: return atoms.density[i];
    case K::Compute: return compute_values.at(i);
  }
  return 0.0;
}

}  // namespace dem

#include "output/dump_fields.h"

#include <cstdio>
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

std::vector<std::string> format_tokens(const std::string& text, std::size_t n_columns,
                                       const std::string& what) {
  std::vector<std::string> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && text[i] == ' ') ++i;
    std::size_t j = i;
    while (j < text.size() && text[j] != ' ') ++j;
    if (j > i) tokens.push_back(text.substr(i, j - i));
    i = j;
  }
  if (tokens.size() < n_columns)
    throw EngineError("dump_modify format string is too short (" + std::to_string(tokens.size()) +
                      " formats for " + std::to_string(n_columns) + " " + what + ")");
  return tokens;
}

std::string integer_format(const std::string& token, const std::string& what) {
  std::string out;
  int conversions = 0;
  for (std::size_t i = 0; i < token.size();) {
    if (token[i] != '%') {
      out += token[i++];
      continue;
    }
    if (i + 1 < token.size() && token[i + 1] == '%') {
      out += "%%";
      i += 2;
      continue;
    }
    std::size_t j = i + 1;
    while (j < token.size() && std::string("-+ 0#").find(token[j]) != std::string::npos) ++j;
    while (j < token.size() && token[j] >= '0' && token[j] <= '9') ++j;
    if (j >= token.size() || (token[j] != 'd' && token[j] != 'i'))
      throw EngineError("dump_modify format '" + token + "': " + what +
                        " needs one %d conversion");
    out += token.substr(i, j - i) + "lld";
    i = j + 1;
    ++conversions;
  }
  if (conversions != 1)
    throw EngineError("dump_modify format '" + token + "': " + what +
                      " needs exactly one %d conversion");
  return out;
}

std::string integer_text(const std::string& format, long long value) {
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#endif
  // `format` was checked by integer_format to hold one long long conversion.
  const int length = std::snprintf(nullptr, 0, format.c_str(), value);
  std::string out(static_cast<std::size_t>(length > 0 ? length : 0) + 1, '\0');
  std::snprintf(out.data(), out.size(), format.c_str(), value);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  out.resize(static_cast<std::size_t>(length > 0 ? length : 0));
  return out;
}

}  // namespace dem

#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "core/particles.h"

namespace dem {

// One per-particle column of dump custom / custom/vtk.
struct DumpField {
  enum class Kind {
    Id, Type, X, Y, Z, Vx, Vy, Vz, Fx, Fy, Fz, OmegaX, OmegaY, OmegaZ, TqX, TqY, TqZ,
    Radius, Diameter, Mass, Density, Compute
  };
  Kind kind = Kind::Id;
  std::string name;        // as written in the deck
  std::string compute_id;  // Kind::Compute only
  bool integer() const { return kind == Kind::Id || kind == Kind::Type; }
};

// Parses dump field words (id type x y z vx vy vz fx fy fz omegax omegay omegaz tqx tqy tqz
// radius diameter mass density c_ID). Throws EngineError naming an unknown or unsupported field.
std::vector<DumpField> parse_dump_fields(const std::vector<std::string>& words);

// Value of a non-compute field for particle i; `compute_values` holds the per-particle values
// of the field's compute (ignored for other kinds).
double dump_field_value(const DumpField& field, const Particles& atoms, std::size_t i,
                        const std::vector<double>& compute_values);

}  // namespace dem

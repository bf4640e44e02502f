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

// The blank-separated formats of `dump_modify format`; throws EngineError when there are fewer
// than `n_columns` (`what` names the columns, e.g. "fields").
std::vector<std::string> format_tokens(const std::string& text, std::size_t n_columns,
                                       const std::string& what);

// The printf format of an integer column from a `dump_modify format` token: exactly one
// %[flags][width]d|i conversion (plus literal text and %%), rewritten to take a long long.
// Throws EngineError naming the token and `what` (e.g. "an integer field") otherwise.
std::string integer_format(const std::string& token, const std::string& what);

// `value` printed with a format returned by integer_format.
std::string integer_text(const std::string& format, long long value);

}  // namespace dem

#include "insert/particle_template_fix.h"

#include <cmath>
#include <sstream>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace dem {
namespace {

// Reads `constant VALUE` after a radius/density keyword; other random styles are refused
// because the engine inserts only constant-size templates.
double constant_value(const std::vector<std::string>& a, std::size_t& i, const std::string& key) {
  if (i + 1 >= a.size()) throw EngineError("'" + key + "' needs a style and a value");
  const std::string& style = a[i + 1];
  if (style != "constant")
    throw EngineError(key + " style '" + style +
                      "' is not supported (only 'constant'; use several templates in a "
                      "particledistribution/discrete for a size distribution)");
  if (i + 2 >= a.size()) throw EngineError("'" + key + " constant' needs a value");
  const double value = parse_double(a[i + 2], key);
  i += 3;
  return value;
}

}  // namespace

ParticleTemplateFix::ParticleTemplateFix(Simulation& sim, const Command& command)
    : Fix(sim, command) {
  const auto& a = args();
  require_args(a, 1, "fix ID group particletemplate/sphere SEED keyword values ...");
  if (parse_int(a[0], "particletemplate seed") <= 0)
    throw EngineError("particletemplate/sphere seed must be a positive integer");
  sphere_.id = id();
  sphere_.group_bit = group_bit();
  double volume_limit = 1e-12;
  bool has_radius = false, has_density = false;
  std::size_t i = 1;
  while (i < a.size()) {
    const std::string& key = a[i];
    if (key == "atom_type") {
      if (i + 1 >= a.size()) throw EngineError("'atom_type' needs a value");
      sphere_.atom_type = static_cast<int>(parse_int(a[i + 1], "atom_type"));
      if (sphere_.atom_type < 1) throw EngineError("atom_type must be >= 1");
      i += 2;
    } else if (key == "radius") {
      sphere_.radius = constant_value(a, i, "radius");
      has_radius = true;
      if (!(sphere_.radius > 0.0)) throw EngineError("radius must be > 0");
    } else if (key == "density") {
      sphere_.density = constant_value(a, i, "density");
      has_density = true;
      if (!(sphere_.density > 0.0)) throw EngineError("density must be > 0");
    } else if (key == "volume_limit") {
      if (i + 1 >= a.size()) throw EngineError("'volume_limit' needs a value");
      volume_limit = parse_double(a[i + 1], "volume_limit");
      if (!(volume_limit > 0.0)) throw EngineError("volume_limit must be > 0");
      i += 2;
    } else if (key == "relative") {
      if (i + 1 >= a.size()) throw EngineError("'relative' needs yes or no");
      if (parse_yes_no(a[i + 1], "relative"))
        throw EngineError("'relative yes' is not supported (radii are absolute, in m)");
      i += 2;
    } else {
      throw EngineError("unknown particletemplate/sphere keyword '" + key + "'");
    }
  }
  // LIGGGHTS requires both, despite the defaults its documentation lists.
  if (!has_density) throw EngineError("have to define 'density'");
  if (!has_radius) throw EngineError("have to define 'radius'");
  if (sphere_.volume() < volume_limit) {
    std::ostringstream os;
    os << "particle volume " << sphere_.volume() << " m^3 is below volume_limit " << volume_limit
       << " m^3 (set a smaller volume_limit if this radius is intended)";
    throw EngineError(os.str());
  }
  // Mass and moment of inertia must be finite numbers for the integrator.
  const double mass = sphere_.mass();
  if (!std::isfinite(sphere_.volume()) || !std::isfinite(mass) ||
      !std::isfinite(mass * sphere_.radius * sphere_.radius)) {
    std::ostringstream os;
    os << "radius " << sphere_.radius << " m and density " << sphere_.density
       << " kg/m^3 give a particle mass or moment of inertia that is not a finite number";
    throw EngineError(os.str());
  }
}

ParticleDistributionFix::ParticleDistributionFix(Simulation& sim, const Command& command)
    : Fix(sim, command) {
  const auto& a = args();
  require_args(a, 2, "fix ID group " + style() + " SEED N template1 weight1 ...");
  if (parse_int(a[0], style() + " seed") <= 0)
    throw EngineError(style() + " seed must be a positive integer");
  const long n = parse_int(a[1], "number of templates");
  if (n < 1) throw EngineError("number of templates must be >= 1");
  if (a.size() != 2 + 2 * static_cast<std::size_t>(n))
    throw EngineError("expected " + std::to_string(n) + " template/weight pairs after N, got " +
                      std::to_string(a.size() - 2) + " words");
  std::vector<SphereTemplate> templates;
  std::vector<double> weights;
  for (long k = 0; k < n; ++k) {
    const std::string& tid = a[2 + 2 * k];
    const auto* t = dynamic_cast<const ParticleTemplateFix*>(sim.find_fix(tid));
    if (!t) throw EngineError("'" + tid + "' is not the ID of a fix particletemplate/sphere");
    templates.push_back(t->sphere());
    weights.push_back(parse_double(a[3 + 2 * k], "weight of template " + tid));
  }
  const bool mass_based = style() != "particledistribution/discrete/numberbased";
  distribution_ =
      std::make_unique<DiscreteDistribution>(std::move(templates), weights, mass_based);
  if (distribution_->renormalised())
    sim.warning("fix " + id() + ": the template weights do not sum to 1; they were normalised");
}

}  // namespace dem

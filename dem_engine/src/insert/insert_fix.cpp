#include "insert/insert_fix.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "core/numbers.h"
#include "core/region.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "insert/overlap_grid.h"
#include "insert/particle_template_fix.h"

namespace dem {
namespace {

const ParticleDistributionFix* find_distribution(const Simulation& sim, const std::string& id) {
  return dynamic_cast<const ParticleDistributionFix*>(sim.find_fix(id));
}

// Largest number of random points drawn to find one inside the region before giving up.
constexpr int kMaxSamples = 100000;

}  // namespace

InsertFix::InsertFix(Simulation& sim, const Command& command)
    : Fix(sim, command),
      random_([&] {
        const auto& a = command.args;
        if (a.size() < 5 || a[3] != "seed")
          throw EngineError("expecting keyword 'seed' after the style name");
        const long seed = parse_int(a[4], "seed");
        if (seed <= 0) throw EngineError("seed must be a positive integer");
        return static_cast<std::uint64_t>(seed);
      }()),
      first_step_(sim.step + 1) {}

void InsertFix::parse_arguments() {
  const auto& a = args();
  const auto need = [&](std::size_t i, std::size_t n) {
    if (i + n >= a.size())
      throw EngineError("keyword '" + a[i] + "' needs " + std::to_string(n) + " value(s)");
  };
  std::size_t i = 2;  // after `seed S`
  while (i < a.size()) {
    const std::string& key = a[i];
    if (key == "distributiontemplate") {
      need(i, 1);
      distribution_id_ = a[i + 1];
      if (!find_distribution(sim_, distribution_id_))
        throw EngineError("'" + distribution_id_ +
                          "' is not the ID of a fix particledistribution/discrete");
      i += 2;
    } else if (key == "maxattempt") {
      need(i, 1);
      maxattempt_ = parse_int(a[i + 1], "maxattempt");
      if (maxattempt_ < 1) throw EngineError("maxattempt must be >= 1");
      i += 2;
    } else if (key == "insert_every") {
      need(i, 1);
      insert_every_ = a[i + 1] == "once" ? 0 : parse_int(a[i + 1], "insert_every");
      if (insert_every_ < 0) throw EngineError("insert_every must be 'once' or >= 1");
      i += 2;
    } else if (key == "start") {
      need(i, 1);
      first_step_ = parse_int(a[i + 1], "start");
      if (first_step_ < sim_.step + 1)
        throw EngineError("'start' step " + std::to_string(first_step_) +
                          " is not after the current step " + std::to_string(sim_.step));
      i += 2;
    } else if (key == "overlapcheck") {
      need(i, 1);
      overlapcheck_ = parse_yes_no(a[i + 1], "overlapcheck");
      i += 2;
    } else if (key == "all_in") {
      need(i, 1);
      all_in_ = parse_yes_no(a[i + 1], "all_in");
      i += 2;
    } else if (key == "random_distribute") {
      need(i, 1);
      if (a[i + 1] != "exact" && a[i + 1] != "uncorrelated")
        throw EngineError("random_distribute must be 'exact' or 'uncorrelated'");
      exact_ = a[i + 1] == "exact";
      i += 2;
    } else if (key == "verbose") {
      need(i, 1);
      verbose_ = parse_yes_no(a[i + 1], "verbose");
      i += 2;
    } else if (key == "compress_tags") {
      need(i, 1);
      if (parse_yes_no(a[i + 1], "compress_tags"))
        throw EngineError("'compress_tags yes' is not supported");
      i += 2;
    } else if (key == "vel") {
      need(i, 1);
      const std::string& style = a[i + 1];
      if (style == "constant") vel_style_ = 0;
      else if (style == "uniform") vel_style_ = 1;
      else if (style == "gaussian") vel_style_ = 2;
      else
        throw EngineError("expecting 'constant', 'uniform' or 'gaussian' after 'vel', got '" +
                          style + "'");
      need(i, vel_style_ == 0 ? 4 : 7);
      for (int k = 0; k < 3; ++k)
        vel_mean_[k] = parse_double(a[i + 2 + k], "vel " + style + " component");
      if (vel_style_ != 0)
        for (int k = 0; k < 3; ++k)
          vel_fluct_[k] = parse_double(a[i + 5 + k], "vel " + style + " fluctuation");
      i += vel_style_ == 0 ? 5 : 8;
    } else if (key == "omega") {
      need(i, 4);
      if (a[i + 1] != "constant") throw EngineError("expecting 'constant' after 'omega'");
      for (int k = 0; k < 3; ++k) omega_[k] = parse_double(a[i + 2 + k], "omega component");
      i += 5;
    } else if (key == "region") {
      need(i, 1);
      region_id_ = a[i + 1];
      sim_.region(region_id_);  // must exist now
      i += 2;
    } else if (key == "ntry_mc") {
      need(i, 1);
      ntry_mc_ = parse_int(a[i + 1], "ntry_mc");
      if (ntry_mc_ < 1000 || ntry_mc_ > 1000000000)
        throw EngineError("ntry_mc must be in 1000..1000000000");
      i += 2;
    } else if (key == "orientation" || key == "set_property" || key == "duration" ||
               key == "extrude_length") {
      throw EngineError("keyword '" + key + "' is not supported");
    } else {
      const std::size_t used = parse_style_keyword(i);
      if (used == 0) throw EngineError("unknown keyword '" + key + "'");
      i += used;
    }
  }
  if (distribution_id_.empty()) throw EngineError("must define a 'distributiontemplate'");
  if (region_id_.empty()) throw EngineError("must define an insertion 'region'");
  next_step_ = first_step_;
}

const DiscreteDistribution& InsertFix::distribution() const {
  const auto* pdd = find_distribution(sim_, distribution_id_);
  if (!pdd)
    throw EngineError("fix " + id() + ": distribution template '" + distribution_id_ +
                      "' no longer exists");
  return pdd->distribution();
}

Region& InsertFix::region() const { return sim_.region(region_id_); }

double InsertFix::max_insert_radius() const {
  const auto* pdd = find_distribution(sim_, distribution_id_);
  return pdd ? pdd->distribution().max_radius() : 0.0;
}

double InsertFix::vector(int index) const {
  if (index == 1) return static_cast<double>(ninserted_);
  if (index == 2) return mass_inserted_;
  return Fix::vector(index);
}

void InsertFix::check_region_inside_box() const {
  const Region& r = region();
  const Domain& box = sim_.domain;
  bool outside = !r.side_in();
  for (int d = 0; d < 3; ++d) {
    const double tol = 1e-12 * (box.hi[d] - box.lo[d]);
    outside = outside || r.extent_lo()[d] < box.lo[d] - tol || r.extent_hi()[d] > box.hi[d] + tol;
  }
  // LIGGGHTS refuses this combination because particles could be placed outside the box.
  if (outside)
    for (int d = 0; d < 3; ++d)
      if (box.boundary[d] == 'f')
        throw EngineError("fix " + id() + ": insertion region '" + region_id_ +
                          "' extends outside the simulation box and a fixed boundary is used");
}

void InsertFix::init() {
  if (!sim_.domain.defined) throw EngineError("fix " + id() + ": insertion before create_box");
  const DiscreteDistribution& dist = distribution();
  for (std::size_t k = 0; k < dist.size(); ++k)
    if (dist.at(k).atom_type > sim_.ntypes)
      throw EngineError("fix " + id() + ": template " + dist.at(k).id + " has atom type " +
                        std::to_string(dist.at(k).atom_type) + " but the box has only " +
                        std::to_string(sim_.ntypes) + " types");
  check_region_inside_box();
  if (prepared_) return;
  const Region& r = region();
  const Domain& box = sim_.domain;
  bool inside_box = r.side_in();
  for (int d = 0; d < 3; ++d) {
    sample_lo_[d] = r.side_in() ? std::max(r.extent_lo()[d], box.lo[d]) : box.lo[d];
    sample_hi_[d] = r.side_in() ? std::min(r.extent_hi()[d], box.hi[d]) : box.hi[d];
    if (!(sample_lo_[d] < sample_hi_[d]))
      throw EngineError("fix " + id() + ": insertion region '" + region_id_ +
                        "' does not overlap the simulation box");
    inside_box = inside_box && r.extent_lo()[d] >= box.lo[d] && r.extent_hi()[d] <= box.hi[d];
  }
  const Vec3 span = sample_hi_ - sample_lo_;
  if (inside_box) {
    region_volume_ = r.volume();
  } else {
    // Monte Carlo volume with its own stream, so the insertion sequence does not depend on it.
    RandomStream mc(static_cast<std::uint64_t>(ntry_mc_) * 7919u + 17u);
    long hits = 0;
    for (long s = 0; s < ntry_mc_; ++s) {
      const Vec3 p{mc.uniform(sample_lo_.x, sample_hi_.x), mc.uniform(sample_lo_.y, sample_hi_.y),
                   mc.uniform(sample_lo_.z, sample_hi_.z)};
      if (r.inside(p)) ++hits;
    }
    region_volume_ = span.x * span.y * span.z * static_cast<double>(hits) /
                     static_cast<double>(ntry_mc_);
  }
  if (!(region_volume_ > 0.0))
    throw EngineError("fix " + id() + ": insertion region '" + region_id_ +
                      "' has no volume inside the simulation box");
  prepare();
  prepared_ = true;
}

bool InsertFix::counts_in_region(std::size_t i) const {
  const Region& r = region();
  const auto& atoms = sim_.atoms;
  return all_in_ ? r.contains_sphere(atoms.x[i], atoms.radius[i]) : r.inside(atoms.x[i]);
}

Vec3 InsertFix::insertion_velocity() {
  Vec3 v = vel_mean_;
  for (int k = 0; k < 3; ++k) {
    if (vel_style_ == 1) v[k] += vel_fluct_[k] * 2.0 * (random_.uniform() - 0.5);
    else if (vel_style_ == 2) v[k] += vel_fluct_[k] * random_.gaussian();
  }
  return v;
}

bool InsertFix::sample_position(double radius, Vec3& p) {
  const Region& r = region();
  const Domain& box = sim_.domain;
  Vec3 lo = sample_lo_, hi = sample_hi_;
  if (all_in_)
    for (int d = 0; d < 3; ++d) {
      lo[d] += radius;
      hi[d] -= radius;
      if (!(lo[d] < hi[d])) return false;
    }
  for (int s = 0; s < kMaxSamples; ++s) {
    for (int d = 0; d < 3; ++d) p[d] = random_.uniform(lo[d], hi[d]);
    if (!(all_in_ ? r.contains_sphere(p, radius) : r.inside(p))) continue;
    // A new particle must lie inside the box; across non-periodic faces it must not cut them.
    bool in_box = true;
    for (int d = 0; d < 3 && in_box; ++d)
      in_box = box.periodic(d) ? p[d] >= box.lo[d] && p[d] < box.hi[d]
                               : p[d] - radius >= box.lo[d] && p[d] + radius <= box.hi[d];
    if (in_box) return true;
  }
  return false;
}

long InsertFix::insert(long n, bool exact) {
  const DiscreteDistribution& dist = distribution();
  const auto* pdd = find_distribution(sim_, distribution_id_);
  const std::vector<std::size_t> order = dist.draw(n, random_, exact);
  auto& atoms = sim_.atoms;
  const Domain& box = sim_.domain;
  const double r_new = dist.max_radius();

  std::optional<OverlapGrid> grid;
  if (overlapcheck_) {
    double r_old = 0.0;
    for (double r : atoms.radius) r_old = std::max(r_old, r);
    grid.emplace(box, 2.0 * std::max(r_new, r_old));
    // Only particles that can touch a new one matter.
    for (std::size_t i = 0; i < atoms.size(); ++i) {
      const double reach = atoms.radius[i] + r_new;
      bool near = true;
      for (int d = 0; d < 3 && near; ++d)
        near = box.periodic(d) || (atoms.x[i][d] >= sample_lo_[d] - reach &&
                                   atoms.x[i][d] <= sample_hi_[d] + reach);
      if (near) grid->add(atoms.x[i], atoms.radius[i]);
    }
  }

  const long max_tries = static_cast<long>(order.size()) * maxattempt_;
  long tries = 0, inserted = 0;
  std::size_t next = 0;
  while (next < order.size() && (!overlapcheck_ || tries < max_tries)) {
    const SphereTemplate& t = dist.at(order[next]);
    Vec3 p;
    if (!sample_position(t.radius, p))
      throw EngineError("fix " + id() + ": no room for a sphere of radius " +
                        std::to_string(t.radius) + " m in region '" + region_id_ +
                        "' inside the simulation box");
    ++tries;
    if (grid && grid->overlaps(p, t.radius)) continue;
    const std::uint32_t mask = 1u | group_bit() | pdd->group_bit() | t.group_bit;
    const std::size_t idx = atoms.add(atoms.next_tag(), t.atom_type, mask, p, t.radius, t.density);
    atoms.v[idx] = insertion_velocity();
    atoms.omega[idx] = omega_;
    if (grid) grid->add(p, t.radius);
    mass_inserted_ += atoms.rmass[idx];
    ++inserted;
    ++next;
  }
  if (inserted > 0) sim_.particles_changed();
  if (inserted < static_cast<long>(order.size()))
    sim_.warning("Particle insertion " + id() + ": less insertions than requested (" +
                 std::to_string(inserted) + " of " + std::to_string(order.size()) + " at step " +
                 std::to_string(sim_.step) + "; raise maxattempt or lower the target)");
  return inserted;
}

long InsertFix::checked_count(double n) const {
  if (std::isnan(n)) throw EngineError("fix " + id() + ": the number to insert is not a number");
  if (!(n >= 1.0)) return 0;
  // A sphere fills at least its own volume: more of the smallest template than fit into the
  // region volume cannot be placed (and would only allocate memory).
  const DiscreteDistribution& dist = distribution();
  double smallest = dist.at(0).volume();
  for (std::size_t k = 1; k < dist.size(); ++k) smallest = std::min(smallest, dist.at(k).volume());
  const double capacity = region_volume_ / smallest;
  if (!(n <= capacity)) {
    std::ostringstream os;
    os << "fix " << id() << ": " << n << " particles per insertion cannot fit into region '"
       << region_id_ << "' (volume " << region_volume_ << " m^3 holds at most " << capacity
       << " spheres of " << smallest << " m^3)";
    throw EngineError(os.str());
  }
  return static_cast<long>(n);
}

void InsertFix::pre_exchange() {
  if (next_step_ < 0 || sim_.step != next_step_) return;
  const long n = count_this_event();
  const double mass_before = mass_inserted_;
  const long inserted = n > 0 ? insert(n, exact_ || completes_total(n)) : 0;
  ninserted_ += inserted;
  if (verbose_ && n > 0) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "INFO: Particle insertion %s: inserted %ld particle templates (mass %g) at step "
                  "%ld\n - a total of %ld particle templates (mass %g) inserted so far.",
                  id().c_str(), inserted, mass_inserted_ - mass_before, sim_.step, ninserted_,
                  mass_inserted_);
    sim_.message(text);
  }
  next_step_ = insert_every_ > 0 && !finished() ? next_step_ + insert_every_ : -1;
}

// --- insert/pack ---------------------------------------------------------------------------

InsertPackFix::InsertPackFix(Simulation& sim, const Command& command) : InsertFix(sim, command) {
  parse_arguments();
  const int targets = (volume_fraction_ > 0.0) + (particles_target_ > 0) + (mass_target_ > 0.0);
  if (targets != 1)
    throw EngineError(
        "must define exactly one of 'volumefraction_region', 'particles_in_region' and "
        "'mass_in_region'");
  if (insert_every_ < 0) throw EngineError("must define 'insert_every'");
}

std::size_t InsertPackFix::parse_style_keyword(std::size_t i) {
  const auto& a = args();
  const std::string& key = a[i];
  if (key != "volumefraction_region" && key != "particles_in_region" && key != "mass_in_region")
    return 0;
  if (i + 1 >= a.size()) throw EngineError("keyword '" + key + "' needs a value");
  if (key == "volumefraction_region") {
    volume_fraction_ = parse_double(a[i + 1], key);
    if (!(volume_fraction_ > 0.0 && volume_fraction_ < 1.0))
      throw EngineError("volumefraction_region must be in (0, 1)");
  } else if (key == "particles_in_region") {
    particles_target_ = parse_int(a[i + 1], key);
    if (particles_target_ < 1) throw EngineError("particles_in_region must be >= 1");
  } else {
    mass_target_ = parse_double(a[i + 1], key);
    if (!(mass_target_ > 0.0)) throw EngineError("mass_in_region must be > 0");
  }
  return 2;
}

void InsertPackFix::prepare() {}

long InsertPackFix::count_this_event() {
  const auto& atoms = sim_.atoms;
  long n_in = 0;
  double volume_in = 0.0, mass_in = 0.0;
  for (std::size_t i = 0; i < atoms.size(); ++i)
    if (counts_in_region(i)) {
      ++n_in;
      const double r = atoms.radius[i];
      volume_in += 4.0 / 3.0 * M_PI * r * r * r;
      mass_in += atoms.rmass[i];
    }
  double n = 0.0;
  const DiscreteDistribution& dist = distribution();
  // Fractional expectations are rounded stochastically so that repeated fills are unbiased.
  if (volume_fraction_ > 0.0)
    n = std::floor((volume_fraction_ * region_volume() - volume_in) / dist.volume_expect() +
                   random_.uniform());
  else if (particles_target_ > 0)
    n = static_cast<double>(particles_target_ - n_in);
  else
    n = std::floor((mass_target_ - mass_in) / dist.mass_expect() + random_.uniform());
  return checked_count(n);
}

// --- insert/rate/region --------------------------------------------------------------------

InsertRateRegionFix::InsertRateRegionFix(Simulation& sim, const Command& command)
    : InsertFix(sim, command) {
  parse_arguments();
  if (insert_every_ < 0) throw EngineError("must define 'insert_every'");
  if (insert_every_ == 0) throw EngineError("'insert_every once' is not allowed");
  if (total_ != -2 && mass_total_ != -2.0)
    throw EngineError("must not define both 'nparticles' and 'mass'");
  if (total_ == -2 && mass_total_ == -2.0)
    throw EngineError("must define either 'nparticles' or 'mass'");
  if (particle_rate_ > 0.0 && mass_rate_ > 0.0)
    throw EngineError("must not define both 'particlerate' and 'massrate'");
  if (!(particle_rate_ > 0.0) && !(mass_rate_ > 0.0))
    throw EngineError("must define either 'particlerate' or 'massrate'");
}

std::size_t InsertRateRegionFix::parse_style_keyword(std::size_t i) {
  const auto& a = args();
  const std::string& key = a[i];
  if (key != "nparticles" && key != "mass" && key != "particlerate" && key != "massrate")
    return 0;
  if (i + 1 >= a.size()) throw EngineError("keyword '" + key + "' needs a value");
  const std::string& value = a[i + 1];
  if (key == "nparticles") {
    total_ = value == "INF" ? -1 : parse_int(value, key);
    if (total_ == 0 || total_ < -1) throw EngineError("nparticles must be >= 1 or INF");
  } else if (key == "mass") {
    mass_total_ = value == "INF" ? -1.0 : parse_double(value, key);
    if (mass_total_ != -1.0 && !(mass_total_ > 0.0)) throw EngineError("mass must be > 0 or INF");
  } else if (key == "particlerate") {
    particle_rate_ = parse_double(value, key);
    if (!(particle_rate_ > 0.0)) throw EngineError("particlerate must be > 0");
  } else {
    mass_rate_ = parse_double(value, key);
    if (!(mass_rate_ > 0.0)) throw EngineError("massrate must be > 0");
  }
  return 2;
}

void InsertRateRegionFix::prepare() {
  const DiscreteDistribution& dist = distribution();
  if (mass_total_ > 0.0) {
    // A total beyond any count the run can reach is as good as INF.
    const double total = mass_total_ / dist.mass_expect();
    total_ = total < 4e18 ? static_cast<long>(total) : -1;
  } else if (mass_total_ == -1.0) {
    total_ = -1;
  }
  if (!(particle_rate_ > 0.0)) particle_rate_ = mass_rate_ / dist.mass_expect();
  // Fixed at the first run, as in LIGGGHTS: later dt changes do not alter the feed per event.
  per_event_ = particle_rate_ * static_cast<double>(insert_every_) * sim_.dt;
  checked_count(per_event_);
}

long InsertRateRegionFix::count_this_event() {
  auto n = checked_count(std::floor(per_event_ + random_.uniform()));
  if (total_ >= 0) n = std::min(n, total_ - ninserted_);
  return std::max(n, 0L);
}

}  // namespace dem

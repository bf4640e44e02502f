#pragma once
#include <cstddef>
#include <string>

#include "core/vec3.h"
#include "fix/fix.h"
#include "insert/random_stream.h"

namespace dem {

class DiscreteDistribution;
class Region;

// Common part of the LIGGGHTS insertion fixes (`seed S distributiontemplate PDD` followed by
// keyword/value pairs): scheduling, keyword parsing, random positions in the region, the overlap
// check and the creation of the particles. Derived styles decide how many to insert per event.
// Global vector: [1] particles inserted so far, [2] their mass (kg).
class InsertFix : public Fix {
 public:
  InsertFix(Simulation& sim, const Command& command);
  void init() override;
  void pre_exchange() override;
  double vector(int index) const override;
  double max_insert_radius() const override;

 protected:
  // Parses all keywords; derived constructors call it once their defaults are set.
  void parse_arguments();
  // Consumes one style keyword at args()[i] and returns the number of words used (0: unknown).
  virtual std::size_t parse_style_keyword(std::size_t i) = 0;
  // Checks the settings at the first run (dt and distribution are known then).
  virtual void prepare() = 0;
  // Number of particles to insert at this event (may be 0).
  virtual long count_this_event() = 0;
  // True when no further insertion events are due after the one at `step`.
  virtual bool finished() const = 0;
  // True when inserting n particles completes a fixed total; the split among templates is then
  // exact even with random_distribute uncorrelated, so the total is not overshot.
  virtual bool completes_total(long /*n*/) const { return false; }

  const DiscreteDistribution& distribution() const;
  Region& region() const;
  // Volume of the insertion region within the box (m^3): analytic when the region lies inside
  // the box, otherwise a Monte Carlo estimate with ntry_mc samples.
  double region_volume() const { return region_volume_; }
  // n as a particle count (0 below 1); throws EngineError for NaN or more spheres of the
  // smallest template than the region volume holds.
  long checked_count(double n) const;
  // True when the particle at local index i counts as inside the region (centre, or the whole
  // sphere with all_in yes).
  bool counts_in_region(std::size_t i) const;
  // Inserts up to n particles (split among templates exactly or independently); returns the
  // number inserted.
  long insert(long n, bool exact);

  RandomStream random_;
  long insert_every_ = -1;  // -1 unset, 0 once
  long ninserted_ = 0;
  double mass_inserted_ = 0.0;
  bool all_in_ = false;

 private:
  bool sample_position(double radius, Vec3& p);
  void check_region_inside_box() const;
  Vec3 insertion_velocity();

  std::string distribution_id_, region_id_;
  long maxattempt_ = 50;
  long first_step_ = 0, next_step_ = 0;
  long ntry_mc_ = 100000;
  bool overlapcheck_ = true, exact_ = true, verbose_ = true;
  int vel_style_ = 0;  // 0 constant, 1 uniform, 2 gaussian
  Vec3 vel_mean_, vel_fluct_, omega_;
  bool prepared_ = false;
  double region_volume_ = 0.0;
  Vec3 sample_lo_, sample_hi_;  // region bounding box within the simulation box
};

// `fix ID group insert/pack seed S distributiontemplate PDD ... region R` with one of
// volumefraction_region F, particles_in_region N or mass_in_region M: fills the region up to the
// target, counting the particles already in it, once or every insert_every steps.
class InsertPackFix : public InsertFix {
 public:
  InsertPackFix(Simulation& sim, const Command& command);

 protected:
  std::size_t parse_style_keyword(std::size_t i) override;
  void prepare() override;
  long count_this_event() override;
  bool finished() const override { return insert_every_ == 0; }

 private:
  double volume_fraction_ = 0.0, mass_target_ = 0.0;
  long particles_target_ = 0;
};

// `fix ID group insert/rate/region seed S distributiontemplate PDD nparticles N|INF (or mass M)
// particlerate R (or massrate M) insert_every K ... region R`: continuous feed of R particles/s,
// inserted every K steps until N particles are in.
class InsertRateRegionFix : public InsertFix {
 public:
  InsertRateRegionFix(Simulation& sim, const Command& command);

 protected:
  std::size_t parse_style_keyword(std::size_t i) override;
  void prepare() override;
  long count_this_event() override;
  bool finished() const override { return total_ >= 0 && ninserted_ >= total_; }
  bool completes_total(long n) const override { return total_ >= 0 && ninserted_ + n >= total_; }

 private:
  long total_ = -2;  // -2 unset, -1 INF
  double mass_total_ = -2.0;
  double particle_rate_ = 0.0, mass_rate_ = 0.0;
  double per_event_ = 0.0;  // expected particles per insertion event
};

}  // namespace dem

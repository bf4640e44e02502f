// Tests of particle insertion, output fixes, dumps and computes: the isolated pieces (overlap
// grid, distributions, time averaging, file helpers) and the fixes driven through deck lines on
// a real Simulation.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "compute/compute_styles.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "insert/discrete_distribution.h"
#include "insert/insert_fix.h"
#include "insert/overlap_grid.h"
#include "insert/random_stream.h"
#include "output/dump_fields.h"
#include "output/output_file.h"
#include "output/time_average.h"
#include "unit_test.h"

namespace fs = std::filesystem;
using dem::DeckError;
using dem::EngineError;
using dem::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A simulation with a 1 cm periodic/fixed box, one atom type and a Hertz pair style.
std::unique_ptr<dem::Simulation> make_simulation(const std::string& boundary = "p f f") {
  dem::EngineOptions options;
  options.log_file = "none";
  options.progress = false;
  auto sim = std::make_unique<dem::Simulation>(options);
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "boundary " + boundary,
      "region box block 0 0.01 0 0.01 0 0.01 units box",
      "create_box 1 box",
      "fix m1 all property/global youngsModulus peratomtype 5e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.3",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
  };
  for (const auto& line : lines) sim->input().run_line(line, {"test", 0});
  return sim;
}

void deck(dem::Simulation& sim, const std::string& line) {
  sim.input().run_line(line, {"test", 1});
}

// Smallest gap (centre distance minus sum of radii) over all pairs, by brute force.
double min_gap(const dem::Simulation& sim) {
  const auto& p = sim.atoms;
  double gap = 1e300;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      gap = std::min(gap, dem::norm(sim.domain.minimum_image(p.x[i] - p.x[j])) - p.radius[i] -
                              p.radius[j]);
  return gap;
}

// Runs the insertion fix `id` at the step it is due (the step after its definition).
void insert_now(dem::Simulation& sim, const std::string& id) {
  dem::Fix& fix = sim.fix(id);
  sim.step += 1;
  fix.init();
  fix.pre_exchange();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

dem::SphereTemplate sphere(const char* id, double radius, double density) {
  dem::SphereTemplate t;
  t.id = id;
  t.radius = radius;
  t.density = density;
  return t;
}

}  // namespace

// --- overlap grid ----------------------------------------------------------------------------

TEST_CASE("io: overlap grid matches brute force with periodic and open dimensions") {
  dem::Domain box;
  box.lo = {0, 0, 0};
  box.hi = {0.01, 0.02, 0.01};
  box.boundary = {'p', 'f', 'p'};
  dem::RandomStream random(12345);
  std::vector<Vec3> x;
  std::vector<double> r;
  dem::OverlapGrid grid(box, 2.0 * 0.0008);
  for (int i = 0; i < 300; ++i) {
    x.push_back({random.uniform(0, 0.01), random.uniform(0, 0.02), random.uniform(0, 0.01)});
    r.push_back(random.uniform(0.0002, 0.0008));
    grid.add(x.back(), r.back());
  }
  CHECK_EQ(grid.size(), std::size_t{300});
  int mismatches = 0, overlapping = 0;
  for (int q = 0; q < 3000; ++q) {
    // Queries also fall slightly outside the box to exercise the periodic wrap.
    const Vec3 p{random.uniform(-0.001, 0.011), random.uniform(-0.001, 0.021),
                 random.uniform(-0.001, 0.011)};
    const double rq = random.uniform(0.0002, 0.0008);
    bool brute = false;
    for (std::size_t s = 0; s < x.size(); ++s)
      brute = brute || dem::norm(box.minimum_image(p - x[s])) < rq + r[s];
    mismatches += brute != grid.overlaps(p, rq);
    overlapping += brute;
  }
  CHECK_EQ(mismatches, 0);
  // Both outcomes occur, so the comparison is not trivially one-sided.
  CHECK(overlapping > 300 && overlapping < 2700);
}

TEST_CASE("io: overlap grid sees a neighbour across the periodic face only") {
  dem::Domain box;
  box.lo = {0, 0, 0};
  box.hi = {1, 1, 1};
  box.boundary = {'p', 'f', 'f'};
  dem::OverlapGrid grid(box, 0.1);
  grid.add({0.01, 0.5, 0.5}, 0.05);
  CHECK(grid.overlaps({0.98, 0.5, 0.5}, 0.05));   // 0.03 apart through x
  CHECK(!grid.overlaps({0.5, 0.98, 0.5}, 0.05));  // y is not periodic
  CHECK(!grid.overlaps({0.12, 0.5, 0.5}, 0.05));  // touching at 0.11 > 0.1: no overlap
}

// --- random numbers and distributions --------------------------------------------------------

TEST_CASE("io: random stream is reproducible and has the right moments") {
  dem::RandomStream a(99), b(99), c(100);
  double sum = 0, sum2 = 0, g = 0, g2 = 0;
  bool same = true, differs = false;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = a.uniform();
    same = same && u == b.uniform();
    differs = differs || u != c.uniform();
    sum += u;
    sum2 += u * u;
  }
  for (int i = 0; i < n; ++i) {
    const double z = a.gaussian();
    g += z;
    g2 += z * z;
  }
  CHECK(same);
  CHECK(differs);
  CHECK_NEAR(sum / n, 0.5, 0.003);
  CHECK_NEAR(sum2 / n - 0.25, 1.0 / 12.0, 0.002);
  CHECK_NEAR(g / n, 0.0, 0.01);
  CHECK_NEAR(g2 / n, 1.0, 0.01);
}

TEST_CASE("io: mass-based distribution converts weights to number fractions") {
  // Equal masses of 1 mm and 2 mm spheres: a 2 mm sphere weighs 8x, so 8 small per large one.
  dem::DiscreteDistribution d({sphere("a", 0.001, 2500), sphere("b", 0.002, 2500)}, {0.5, 0.5},
                              true);
  const double m1 = 4.0 / 3.0 * kPi * 1e-9 * 2500;
  CHECK(!d.renormalised());
  CHECK_NEAR(d.number_fraction(0), 8.0 / 9.0, 1e-12);
  CHECK_NEAR(d.number_fraction(1), 1.0 / 9.0, 1e-12);
  CHECK_NEAR(d.mass_expect(), 16.0 / 9.0 * m1, 1e-12 * m1);
  CHECK_NEAR(d.volume_expect(), 16.0 / 9.0 * 4.0 / 3.0 * kPi * 1e-9, 1e-20);
  CHECK_NEAR(d.max_radius(), 0.002, 0.0);

  dem::DiscreteDistribution by_number({sphere("a", 0.001, 2500), sphere("b", 0.002, 2500)},
                                      {2.0, 2.0}, false);
  CHECK(by_number.renormalised());
  CHECK_NEAR(by_number.number_fraction(0), 0.5, 1e-12);
  CHECK_NEAR(by_number.mass_fraction(1), 8.0 / 9.0, 1e-12);

  CHECK_THROWS_AS(dem::DiscreteDistribution({sphere("a", 0.001, 1)}, {0.0}, true), EngineError);
  CHECK_THROWS_AS(dem::DiscreteDistribution({sphere("a", 0.001, 1)}, {0.5, 0.5}, true),
                  EngineError);
}

TEST_CASE("io: exact draws sum to n, are unbiased and place large spheres first") {
  dem::DiscreteDistribution d({sphere("a", 0.001, 2500), sphere("b", 0.002, 2500)}, {0.5, 0.5},
                              true);
  dem::RandomStream random(7);
  const auto nine = d.draw(9, random, true);
  CHECK_EQ(nine.size(), std::size_t{9});
  CHECK_EQ(nine[0], std::size_t{1});  // the one large sphere comes first
  for (std::size_t k = 1; k < 9; ++k) CHECK_EQ(nine[k], std::size_t{0});

  // n = 10: 8.89 small and 1.11 large expected; the remainders decide the last one.
  double large = 0;
  const int trials = 20000;
  for (int t = 0; t < trials; ++t) {
    const auto v = d.draw(10, random, true);
    CHECK_EQ(v.size(), std::size_t{10});
    for (auto k : v) large += k == 1;
  }
  CHECK_NEAR(large / trials, 10.0 / 9.0, 0.01);

  double total = 0;
  for (int t = 0; t < trials; ++t) total += static_cast<double>(d.draw(10, random, false).size());
  CHECK_NEAR(total / trials, 10.0, 0.02);
}

// --- time averaging --------------------------------------------------------------------------

TEST_CASE("io: time average one, running, window and off follow LAMMPS ave/time") {
  using Mode = dem::TimeAverage::Mode;
  // Samples 1..12 in blocks of 2: block averages 1.5, 3.5, 5.5, 7.5, 9.5, 11.5.
  dem::TimeAverage one(2, 2, Mode::One, 0, {false, true});
  dem::TimeAverage running(1, 2, Mode::Running, 0, {});
  dem::TimeAverage window(1, 2, Mode::Window, 3, {});
  std::vector<double> blocks;
  for (int s = 1; s <= 12; ++s) {
    const bool done = one.add({double(s), 10.0 * s});
    running.add({double(s)});
    window.add({double(s)});
    CHECK_EQ(done, s % 2 == 0);
    if (!done) continue;
    blocks.push_back(s - 0.5);
    CHECK_NEAR(one.value(0), s - 0.5, 1e-12);
    CHECK_NEAR(one.value(1), 10.0 * s, 1e-12);  // off: latest sample
    double all = 0;
    for (double b : blocks) all += b;
    CHECK_NEAR(running.value(0), all / blocks.size(), 1e-12);
    double last = 0;
    const std::size_t m = std::min<std::size_t>(3, blocks.size());
    for (std::size_t k = blocks.size() - m; k < blocks.size(); ++k) last += blocks[k];
    CHECK_NEAR(window.value(0), last / m, 1e-12);
  }
}

// --- files and dump fields -------------------------------------------------------------------

TEST_CASE("io: step patterns and atomic file writes") {
  CHECK_EQ(dem::expand_step_pattern("post/d*.vtk", 1200, 0), std::string("post/d1200.vtk"));
  CHECK_EQ(dem::expand_step_pattern("d*.vtk", 12, 6), std::string("d000012.vtk"));
  CHECK_EQ(dem::expand_step_pattern("plain.txt", 12, 6), std::string("plain.txt"));
  const fs::path dir = fs::temp_directory_path() / "dem_io_atomic";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "a.txt").string();
  dem::write_file_atomically(path, "first\n");
  dem::write_file_atomically(path, "second\n");
  CHECK_EQ(read_text(path), std::string("second\n"));
  CHECK_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
  CHECK_THROWS_AS(dem::write_file_atomically((dir / "missing" / "b.txt").string(), "x"),
                  EngineError);
  fs::remove_all(dir);
}

TEST_CASE("io: dump fields parse and read particle values") {
  const auto fields = dem::parse_dump_fields({"id", "type", "x", "vz", "omegay", "radius",
                                              "diameter", "mass", "density", "c_cn"});
  CHECK_EQ(fields.size(), std::size_t{10});
  CHECK(fields[0].integer() && fields[1].integer() && !fields[2].integer());
  CHECK_EQ(fields[9].compute_id, std::string("cn"));
  dem::Particles p;
  p.add(7, 2, 1u, {0.1, 0.2, 0.3}, 0.002, 2500);
  p.v[0] = {1, 2, 3};
  p.omega[0] = {4, 5, 6};
  const std::vector<double> none, cn = {3.0};
  CHECK_EQ(dem::dump_field_value(fields[0], p, 0, none), 7.0);
  CHECK_EQ(dem::dump_field_value(fields[1], p, 0, none), 2.0);
  CHECK_EQ(dem::dump_field_value(fields[2], p, 0, none), 0.1);
  CHECK_EQ(dem::dump_field_value(fields[3], p, 0, none), 3.0);
  CHECK_EQ(dem::dump_field_value(fields[4], p, 0, none), 5.0);
  CHECK_EQ(dem::dump_field_value(fields[6], p, 0, none), 0.004);
  CHECK_NEAR(dem::dump_field_value(fields[7], p, 0, none), 4.0 / 3.0 * kPi * 8e-9 * 2500, 1e-15);
  CHECK_EQ(dem::dump_field_value(fields[8], p, 0, none), 2500.0);
  CHECK_EQ(dem::dump_field_value(fields[9], p, 0, cn), 3.0);
  CHECK_THROWS_AS(dem::parse_dump_fields({"id", "xs"}), EngineError);
  CHECK_THROWS_AS(dem::parse_dump_fields({"c_stress[1]"}), EngineError);
}

// --- insertion fixes on a real simulation ------------------------------------------------------

TEST_CASE("io: insert/pack particles_in_region reaches its target without overlaps") {
  auto sim = make_simulation();
  deck(*sim, "region ins block 0.001 0.009 0.001 0.009 0.001 0.009 units box");
  deck(*sim, "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 "
             "radius constant 0.0004");
  deck(*sim, "fix pdd all particledistribution/discrete 32452843 1 pts 1.0");
  deck(*sim, "fix ins all insert/pack seed 100001 distributiontemplate pdd insert_every once "
             "overlapcheck yes all_in yes vel constant 0.1 0 -0.2 particles_in_region 400 "
             "region ins");
  CHECK_NEAR(sim->max_radius(), 0.0004, 0.0);
  insert_now(*sim, "ins");
  CHECK_EQ(sim->atoms.size(), std::size_t{400});
  CHECK(min_gap(*sim) >= 0.0);
  const dem::Region& r = sim->region("ins");
  bool all_inside = true, moving = true;
  for (std::size_t i = 0; i < sim->atoms.size(); ++i) {
    all_inside = all_inside && r.contains_sphere(sim->atoms.x[i], 0.0004);
    moving = moving && sim->atoms.v[i].x == 0.1 && sim->atoms.v[i].z == -0.2;
  }
  CHECK(all_inside);
  CHECK(moving);
  CHECK_EQ(sim->atoms.tag.back(), std::int64_t{400});
  CHECK_EQ(sim->fix_value("ins", 1), 400.0);
  CHECK_NEAR(sim->fix_value("ins", 2), 400 * 4.0 / 3.0 * kPi * 0.064e-9 * 2500, 1e-12);
  // Inserted once: a second event does not happen.
  sim->step += 1;
  sim->fix("ins").pre_exchange();
  CHECK_EQ(sim->atoms.size(), std::size_t{400});
}

TEST_CASE("io: insert/pack mass_in_region counts particles already in the region") {
  auto sim = make_simulation();
  deck(*sim, "region ins cylinder z 0.005 0.005 0.004 0.0 0.01 units box");
  deck(*sim, "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 1000 "
             "radius constant 0.0005");
  deck(*sim, "fix pdd all particledistribution/discrete 32452843 1 pts 1.0");
  const double m = 4.0 / 3.0 * kPi * 0.125e-9 * 1000;
  std::ostringstream target;
  target.precision(17);
  target << 100.0 * m;
  deck(*sim, "fix ins all insert/pack seed 7919 distributiontemplate pdd insert_every 5 "
             "overlapcheck yes mass_in_region " + target.str() + " region ins");
  insert_now(*sim, "ins");
  CHECK_EQ(sim->atoms.size(), std::size_t{100});
  CHECK_NEAR(sim->fix_value("ins", 2), 100.0 * m, 1e-9 * m);
  // Half of the particles are removed; the next event (5 steps later) refills the mass.
  std::vector<char> gone(100, 0);
  for (std::size_t i = 0; i < 50; ++i) gone[2 * i] = 1;
  sim->atoms.remove(gone);
  sim->particles_changed();
  sim->step += 4;
  sim->fix("ins").pre_exchange();
  CHECK_EQ(sim->atoms.size(), std::size_t{50});  // not due yet
  sim->step += 1;
  sim->fix("ins").pre_exchange();
  CHECK_EQ(sim->atoms.size(), std::size_t{100});
  CHECK_EQ(sim->fix_value("ins", 1), 150.0);
  CHECK(min_gap(*sim) >= 0.0);
}

TEST_CASE("io: insertion is deterministic for a seed and differs for another") {
  std::vector<std::vector<double>> runs;
  for (const char* seed : {"100003", "100003", "100019"}) {
    auto sim = make_simulation();
    deck(*sim, "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 "
               "radius constant 0.0005");
    deck(*sim, "fix pdd all particledistribution/discrete 32452843 1 pts 1.0");
    deck(*sim, std::string("fix ins all insert/pack seed ") + seed +
                   " distributiontemplate pdd insert_every once volumefraction_region 0.2 "
                   "region box");
    insert_now(*sim, "ins");
    std::vector<double> xs;
    for (const Vec3& x : sim->atoms.x) xs.push_back(x.x + 10 * x.y + 100 * x.z);
    runs.push_back(xs);
  }
  CHECK(!runs[0].empty());
  CHECK(runs[0] == runs[1]);
  CHECK(runs[0] != runs[2]);
}

TEST_CASE("io: insertion commands reject bad settings") {
  auto sim = make_simulation();
  deck(*sim, "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 "
             "radius constant 0.0005");
  deck(*sim, "fix pdd all particledistribution/discrete 32452843 1 pts 1.0");
  CHECK_THROWS_AS(deck(*sim, "fix t2 all particletemplate/sphere 1 radius gaussian 1 0.1"),
                  DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix t3 all particletemplate/sphere 1 density constant 2500"),
                  DeckError);  // no radius
  CHECK_THROWS_AS(deck(*sim, "fix p2 all particledistribution/discrete 1 2 pts 1.0"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix p3 all particledistribution/discrete 1 1 nosuch 1.0"),
                  DeckError);
  // No target, two targets, no region, unknown keyword.
  CHECK_THROWS_AS(deck(*sim, "fix i1 all insert/pack seed 1 distributiontemplate pdd "
                             "insert_every once region box"),
                  DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix i2 all insert/pack seed 1 distributiontemplate pdd "
                             "insert_every once particles_in_region 3 mass_in_region 1 region box"),
                  DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix i3 all insert/pack seed 1 distributiontemplate pdd "
                             "insert_every once particles_in_region 3"),
                  DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix i4 all insert/pack seed 1 distributiontemplate pdd "
                             "insert_every once particles_in_region 3 region box colour red"),
                  DeckError);
  CHECK_THROWS_AS(deck(*sim, "fix i5 all insert/rate/region seed 1 distributiontemplate pdd "
                             "nparticles 10 insert_every 10 region box"),
                  DeckError);
  try {
    deck(*sim, "fix i6 all insert/pack seed 1 distributiontemplate pdd insert_every once "
               "particles_in_region 3 region box volumefraction_region 1.5");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK(std::string(e.what()).find("volumefraction_region") != std::string::npos);
  }
}

TEST_CASE("io: insertion refuses a region reaching outside a box with fixed walls") {
  auto sim = make_simulation("f f f");
  deck(*sim, "region big block -0.001 0.01 0 0.01 0 0.01 units box");
  deck(*sim, "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 "
             "radius constant 0.0005");
  deck(*sim, "fix pdd all particledistribution/discrete 32452843 1 pts 1.0");
  deck(*sim, "fix ins all insert/pack seed 1 distributiontemplate pdd insert_every once "
             "particles_in_region 3 region big");
  sim->step += 1;
  CHECK_THROWS_AS(sim->fix("ins").init(), EngineError);
}

// --- computes ----------------------------------------------------------------------------------

TEST_CASE("io: erotate/sphere, contact/atom and reduce give analytic values") {
  auto sim = make_simulation();
  auto& p = sim->atoms;
  // Two touching spheres (overlap 0.1 mm), one apart; group "pair" holds the first two.
  p.add(p.next_tag(), 1, 1u, {0.002, 0.005, 0.005}, 0.001, 2000);
  p.add(p.next_tag(), 1, 1u, {0.0039, 0.005, 0.005}, 0.001, 2000);
  p.add(p.next_tag(), 1, 1u, {0.008, 0.005, 0.005}, 0.0005, 2000);
  p.omega[0] = {0, 0, 10};
  p.omega[2] = {3, 4, 0};
  p.v[1] = {0, 0, -2};
  sim->neighbor.build(p, sim->domain);
  deck(*sim, "compute rot all erotate/sphere");
  deck(*sim, "compute cn all contact/atom");
  deck(*sim, "compute sum all reduce sum c_cn vz");
  deck(*sim, "compute top all reduce max z");
  const double m0 = 4.0 / 3.0 * kPi * 1e-9 * 2000, m2 = m0 / 8;
  const double expected = 0.5 * 0.4 * (m0 * 1e-6 * 100 + m2 * 0.25e-6 * 25);
  CHECK_NEAR(sim->compute_value("rot", 0), expected, 1e-15);
  const auto cn = sim->compute("cn").peratom_values();
  CHECK(cn == std::vector<double>({1.0, 1.0, 0.0}));
  CHECK_EQ(sim->compute_value("sum", 1), 2.0);
  CHECK_EQ(sim->compute_value("sum", 2), -2.0);
  CHECK_EQ(sim->compute_value("top", 0), 0.005);
  CHECK_THROWS_AS(sim->compute_value("sum", 0), EngineError);
  CHECK_THROWS_AS(deck(*sim, "compute bad all stress/atom"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "compute bad all reduce sum c_rot"), DeckError);
}

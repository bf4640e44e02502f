// Tests of `compute pair/gran/local` and `dump local`: column layout and keyword errors, the
// values against the forces of the force loop, the orientation of pairs across a periodic
// boundary, the text layout of the dump, and that reading the compute changes nothing.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "compute/compute_pair_gran_local.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "output/local_dump.h"
#include "unit_test.h"

namespace fs = std::filesystem;
using dem::DeckError;
using dem::EngineError;
using dem::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Fresh directory under the system temp dir, removed with its contents on destruction.
class ScratchDir {
 public:
  ScratchDir() {
    static int counter = 0;
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() /
            ("dem_local_dump_test_" + std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void deck(dem::Simulation& sim, const std::string& line) {
  sim.input().run_line(line, {"test", 1});
}

// Two 2 mm spheres of one type in a 1 cm box, overlapping by 10 um along x; particle 1 moves
// and spins so that the contact has a tangential force. `rolling` adds rolling_friction epsd2.
std::unique_ptr<dem::Simulation> make_pair(const std::string& boundary = "f f f",
                                           bool rolling = false) {
  dem::EngineOptions options;
  options.log_file = "none";
  options.progress = false;
  auto sim = std::make_unique<dem::Simulation>(options);
  const bool periodic_x = boundary[0] == 'p';
  // Across the periodic x boundary: particle 1 near x = 0.01, particle 2 near x = 0 (its
  // image at +x of particle 1, as particle 2 without periodic boundaries).
  const std::string x1 = periodic_x ? "0.00999" : "0.004";
  const std::string x2 = periodic_x ? "0.00198" : "0.00599";
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "atom_modify map array",
      "boundary " + boundary,
      "newton off",
      "communicate single vel yes",
      "region box block 0 0.01 0 0.01 0 0.01 units box",
      "create_box 1 box",
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
      "fix m1 all property/global youngsModulus peratomtype 5e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.3",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
      "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1",
      std::string("pair_style gran model hertz tangential history") +
          (rolling ? " rolling_friction epsd2" : ""),
      "pair_coeff * *",
      "timestep 1e-6",
      "create_atoms 1 single " + x1 + " 0.005 0.005 units box",
      "set atom 1 diameter 0.002 density 2500 vx 0.02 vy 0.01 omegaz 5",
      "create_atoms 1 single " + x2 + " 0.005 0.005 units box",
      "set atom 2 diameter 0.002 density 2500 omegay -3",
      "fix integr all nve/sphere",
  };
  for (const auto& line : lines) deck(*sim, line);
  return sim;
}

const dem::LocalCompute& local(const dem::Simulation& sim, const std::string& id) {
  return dynamic_cast<const dem::LocalCompute&>(sim.compute(id));
}

Vec3 row_vec(const dem::LocalArray& a, std::size_t row, std::size_t column) {
  return {a.at(row, column), a.at(row, column + 1), a.at(row, column + 2)};
}

const char* const kAllKeywords =
    "pos vel id force force_normal force_tangential torque history contactArea delta";

}  // namespace

TEST_CASE("local dump: column words parse into compute columns and index") {
  const auto columns = dem::parse_local_dump_columns({"index", "c_c[1]", "c_pairs[12]"});
  CHECK_EQ(columns.size(), std::size_t{3});
  CHECK(columns[0].is_index());
  CHECK_EQ(columns[1].compute_id, std::string("c"));
  CHECK_EQ(columns[1].column, std::size_t{0});
  CHECK_EQ(columns[2].compute_id, std::string("pairs"));
  CHECK_EQ(columns[2].column, std::size_t{11});
  CHECK_EQ(columns[2].name, std::string("c_pairs[12]"));
  for (const char* bad : {"c_c", "c_c[0]", "c_c[x]", "c_[1]", "c_c[1", "f_w[1]", "v_a", "x"})
    CHECK_THROWS_AS(dem::parse_local_dump_columns({bad}), EngineError);
}

TEST_CASE("local dump: pair/gran/local has LIGGGHTS' column counts and refuses bad keywords") {
  auto sim = make_pair();
  deck(*sim, "compute c all pair/gran/local");  // default: all but fn, ft and delta
  CHECK_EQ(local(*sim, "c").local_columns(), std::size_t{6 + 6 + 3 + 3 + 3 + 3 + 1});
  deck(*sim, "uncompute c");
  deck(*sim, "compute c all pair/gran/local delta pos pos");  // order and repeats do not count
  CHECK_EQ(local(*sim, "c").local_columns(), std::size_t{7});
  deck(*sim, "uncompute c");
  deck(*sim, std::string("compute c all pair/gran/local ") + kAllKeywords);
  CHECK_EQ(local(*sim, "c").local_columns(), std::size_t{32});
  // One per pair style, as LIGGGHTS.
  CHECK_THROWS_AS(deck(*sim, "compute d all pair/gran/local"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "compute e all pair/gran/local torque bogus"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "compute e all pair/gran/local heatFlux"), DeckError);

  auto rolling = make_pair("f f f", true);  // the history holds the rolling torque too
  deck(*rolling, "compute c all pair/gran/local history");
  CHECK_EQ(local(*rolling, "c").local_columns(), std::size_t{6});

  // Defined before pair_style, or after the first run: refused, as by LIGGGHTS 3.8.
  dem::EngineOptions options;
  options.log_file = "none";
  dem::Simulation bare(options);
  deck(bare, "units si");
  deck(bare, "atom_style granular");
  deck(bare, "region box block 0 1 0 1 0 1 units box");
  deck(bare, "create_box 1 box");
  CHECK_THROWS_AS(deck(bare, "compute c all pair/gran/local"), DeckError);
  auto late = make_pair();
  deck(*late, "run 2");
  CHECK_THROWS_AS(deck(*late, "compute c all pair/gran/local"), DeckError);
}

TEST_CASE("local dump: values at the set-up of a run are those the force loop integrates") {
  auto sim = make_pair();
  deck(*sim, std::string("compute c all pair/gran/local ") + kAllKeywords);
  deck(*sim, "run 0");  // set-up: forces from the current state, history unchanged
  const dem::LocalArray a = local(*sim, "c").local_array();
  CHECK_EQ(a.columns, std::size_t{32});
  CHECK_EQ(a.rows(), std::size_t{1});
  if (a.rows() != 1) return;
  const auto& p = sim->atoms;
  // pos, vel: particle 1 then particle 2.
  CHECK_EQ(row_vec(a, 0, 0).x, p.x[0].x);
  CHECK_EQ(row_vec(a, 0, 3).x, p.x[1].x);
  CHECK_EQ(row_vec(a, 0, 6).y, 0.01);
  CHECK_EQ(row_vec(a, 0, 9).y, 0.0);
  // id: 1 2, not periodic.
  CHECK_EQ(a.at(0, 12), 1.0);
  CHECK_EQ(a.at(0, 13), 2.0);
  CHECK_EQ(a.at(0, 14), 0.0);
  // force and torque on particle 1 are the ones integrated (the only contact).
  const Vec3 force = row_vec(a, 0, 15);
  CHECK_EQ(force.x, p.f[0].x);
  CHECK_EQ(force.y, p.f[0].y);
  CHECK_EQ(force.z, p.f[0].z);
  CHECK(force.x < 0.0);  // repulsive: particle 2 lies at +x
  CHECK(std::fabs(force.y) > 0.0);  // tangential (damping of the sliding velocity)
  const Vec3 torque = row_vec(a, 0, 24);
  CHECK_EQ(torque.y, p.torque[0].y);
  CHECK_EQ(torque.z, p.torque[0].z);
  // force_normal along the line of centres, force_tangential normal to it, summing to force.
  const Vec3 fn = row_vec(a, 0, 18), ft = row_vec(a, 0, 21);
  const Vec3 d = p.x[1] - p.x[0];
  CHECK_NEAR(dem::norm(dem::cross(fn, d)), 0.0, 1e-12 * dem::norm(fn) * dem::norm(d));
  CHECK_NEAR(dem::dot(ft, d), 0.0, 1e-12 * dem::norm(force) * dem::norm(d));
  CHECK_NEAR(fn.x + ft.x, force.x, 1e-15 * dem::norm(force));
  CHECK_NEAR(fn.y + ft.y, force.y, 1e-15 * dem::norm(force));
  // history: zero at the start of a contact; contact area and overlap of the two spheres.
  for (std::size_t k = 27; k < 30; ++k) CHECK_EQ(a.at(0, k), 0.0);
  const double r = dem::norm(d), radius = 0.001;
  CHECK_NEAR(a.at(0, 30), kPi * (radius * radius - 0.25 * r * r), 1e-12 * kPi * radius * radius);
  CHECK_NEAR(a.at(0, 31), 2 * radius - r, 1e-15);
  CHECK_NEAR(a.at(0, 31), 1e-5, 1e-12);
}

TEST_CASE("local dump: a pair across a periodic boundary lists the larger id first") {
  auto sim = make_pair("p f f");
  deck(*sim, "compute c all pair/gran/local pos id force delta");
  deck(*sim, "run 0");
  const dem::LocalArray a = local(*sim, "c").local_array();
  CHECK_EQ(a.rows(), std::size_t{1});
  if (a.rows() != 1) return;
  CHECK_EQ(a.at(0, 6), 2.0);
  CHECK_EQ(a.at(0, 7), 1.0);
  CHECK_EQ(a.at(0, 8), 1.0);  // periodic flag
  const auto& p = sim->atoms;
  CHECK_EQ(a.at(0, 0), p.x[1].x);  // first: particle 2
  CHECK_EQ(a.at(0, 3), p.x[0].x);
  const Vec3 force = row_vec(a, 0, 9);  // on particle 2, from particle 1's image at -x
  CHECK_EQ(force.x, p.f[1].x);
  CHECK_EQ(force.y, p.f[1].y);
  CHECK(force.x > 0.0);
  CHECK_NEAR(a.at(0, 12), 1e-5, 1e-12);
  // Both move by 50 um: particle 1 leaves through x = 0.01 and is not wrapped before the next
  // neighbour build; the output maps it into the box.
  deck(*sim, "set group all vx 0.5");
  deck(*sim, "run 100");
  CHECK(sim->atoms.x[0].x > 0.01);
  const dem::LocalArray b = local(*sim, "c").local_array();
  CHECK_EQ(b.rows(), std::size_t{1});
  if (b.rows() != 1) return;
  CHECK(b.at(0, 3) >= 0.0 && b.at(0, 3) < 0.0001);
  CHECK_EQ(b.at(0, 3), sim->atoms.x[0].x - 0.01);
}

TEST_CASE("local dump: reading the compute changes neither history nor trajectory") {
  ScratchDir dir;
  std::vector<Vec3> x[2];
  for (int with = 0; with < 2; ++with) {
    auto sim = make_pair("p f f", true);
    if (with) {
      deck(*sim, std::string("compute c all pair/gran/local ") + kAllKeywords);
      deck(*sim, "dump d all local 7 " + dir.file("contacts.txt") + " c_c[16] c_c[17]");
    }
    deck(*sim, "run 200");
    if (with) {
      const std::vector<double> history = sim->neighbor.history;
      const dem::LocalArray first = local(*sim, "c").local_array();
      const dem::LocalArray second = local(*sim, "c").local_array();
      CHECK(first.values == second.values);
      CHECK(sim->neighbor.history == history);
      CHECK_EQ(first.rows(), std::size_t{1});
      if (first.rows() == 1) CHECK(std::fabs(first.at(0, 28)) > 0.0);  // spring (y) grew
    }
    deck(*sim, "run 100");
    x[with] = sim->atoms.x;
  }
  CHECK_EQ(x[0].size(), x[1].size());
  for (std::size_t i = 0; i < x[0].size(); ++i) {
    CHECK_EQ(x[0][i].x, x[1][i].x);
    CHECK_EQ(x[0][i].y, x[1][i].y);
  }
}

TEST_CASE("local dump: text layout, index, formats, every, first and undump") {
  ScratchDir dir;
  auto sim = make_pair();
  deck(*sim, "compute c all pair/gran/local id delta");
  const std::string path = dir.file("contacts.txt");
  deck(*sim, "dump d all local 5 " + path + " index c_c[1] c_c[2] c_c[4]");
  deck(*sim, "dump_modify d format \"%3d %g %g %.4e\"");
  deck(*sim, "run 0");
  CHECK_EQ(read_text(path), std::string("ITEM: TIMESTEP\n0\n"
                                        "ITEM: NUMBER OF ENTRIES\n1\n"
                                        "ITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n0 0.01\n"
                                        "ITEM: ENTRIES index c_c[1] c_c[2] c_c[4] \n"
                                        "  1 1 2 1.0000e-05 \n"));
  deck(*sim, "dump_modify d format none");
  deck(*sim, "run 12");  // steps 5 and 10
  const std::string text = read_text(path);
  CHECK(text.find("ITEM: TIMESTEP\n5\n") != std::string::npos);
  CHECK(text.find("ITEM: TIMESTEP\n10\n") != std::string::npos);
  CHECK(text.find("ITEM: TIMESTEP\n12\n") == std::string::npos);
  CHECK(text.find("\n1 1 2 ") != std::string::npos);  // default formats: %d, %g
  // An empty snapshot (a group without particles); `first yes` writes at the first step it is
  // called.
  auto other = make_pair();
  deck(*other, "group none id 5");
  deck(*other, "compute n none pair/gran/local id");
  deck(*other, "run 12");
  const std::string empty = dir.file("empty.txt");
  deck(*other, "dump e all local 100 " + empty + " c_n[1]");
  deck(*other, "dump_modify e first yes every 50");
  deck(*other, "run 40");
  CHECK_EQ(read_text(empty), std::string("ITEM: TIMESTEP\n12\n"
                                         "ITEM: NUMBER OF ENTRIES\n0\n"
                                         "ITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n0 0.01\n"
                                         "ITEM: ENTRIES c_n[1] \n"
                                         "ITEM: TIMESTEP\n50\n"
                                         "ITEM: NUMBER OF ENTRIES\n0\n"
                                         "ITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n0 0.01\n"
                                         "ITEM: ENTRIES c_n[1] \n"));
  deck(*other, "undump e");
  deck(*other, "run 60");
  CHECK(read_text(empty).find("ITEM: TIMESTEP\n100\n") == std::string::npos);
  // One file per snapshot with '*'.
  deck(*sim, "dump s all local 10 " + dir.file("c_*.txt") + " c_c[4]");
  deck(*sim, "dump_modify s pad 5");
  deck(*sim, "run 10");  // steps 12..22: only 20 is a multiple of 10
  CHECK(fs::exists(dir.file("c_00020.txt")));
  CHECK(!fs::exists(dir.file("c_00012.txt")));
  CHECK(read_text(dir.file("c_00020.txt")).rfind("ITEM: TIMESTEP\n20\n", 0) == 0);

  // Refused: integer formats of compute values (LIGGGHTS prints garbage), short formats,
  // sort, columns out of range or of a compute without local values, no compute column.
  CHECK_THROWS_AS(deck(*sim, "dump_modify d format \"%d %d %d %d\""), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump_modify d format \"%d %g\""), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump_modify d format \"%g %g %g %g\""), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump_modify d sort id"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + " c_c[5]"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + " c_c"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + " index"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + " c_missing[1]"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 0 " + path + " c_c[1]"), DeckError);
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + ".gz c_c[1]"), DeckError);
  deck(*sim, "compute ke all erotate/sphere");
  CHECK_THROWS_AS(deck(*sim, "dump x all local 5 " + path + " c_ke[1]"), DeckError);
}

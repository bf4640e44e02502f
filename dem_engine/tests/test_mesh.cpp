// Tests of walls and meshes: STL reading and writing, triangle geometry, the particle-triangle
// candidate search, contact deduplication and history, primitive walls, the servo law and the
// mesh fixes driven through deck lines on a real Simulation.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/simulation.h"
#include "deck/errors.h"
#include "mesh/fix_mesh_surface.h"
#include "mesh/mesh_contacts.h"
#include "mesh/primitive_wall.h"
#include "mesh/servo_controller.h"
#include "mesh/stl_io.h"
#include "mesh/tri_mesh.h"
#include "mesh/tri_neighbor_list.h"
#include "mesh/triangle_geometry.h"
#include "unit_test.h"

namespace fs = std::filesystem;
using dem::ClosestPoint;
using dem::EngineError;
using dem::MeshContact;
using dem::Triangle;
using dem::TriMesh;
using dem::TriRegion;
using dem::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A scratch directory removed when the test case ends.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("dem_mesh_test_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string error_text(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Closest point of a segment, by clamped projection.
Vec3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
  return a + t * ab;
}

// Independent closest point: the projection onto the plane if it falls inside the triangle
// (barycentric coordinates from areas), otherwise the best of the three edges.
Vec3 brute_closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = dem::triangle_normal(a, b, c);
  const Vec3 q = p - dot(p - a, n) * n;
  const double area = dot(cross(b - a, c - a), n);
  const double u = dot(cross(b - q, c - q), n) / area;
  const double v = dot(cross(c - q, a - q), n) / area;
  const double w = 1.0 - u - v;
  if (u >= 0 && v >= 0 && w >= 0) return q;
  Vec3 best = closest_on_segment(p, a, b);
  for (const Vec3& cand : {closest_on_segment(p, b, c), closest_on_segment(p, c, a)})
    if (norm2(cand - p) < norm2(best - p)) best = cand;
  return best;
}

std::vector<Triangle> square_plate(double half, double z) {
  // Two triangles sharing the diagonal (-h,-h)-(h,h).
  const Vec3 p0{-half, -half, z}, p1{half, -half, z}, p2{half, half, z}, p3{-half, half, z};
  return {Triangle{{p0, p1, p2}}, Triangle{{p0, p2, p3}}};
}

std::vector<Triangle> cylinder_mesh(double radius, double z0, double z1, int segments) {
  std::vector<Triangle> tris;
  for (int k = 0; k < segments; ++k) {
    const double a0 = 2 * kPi * k / segments, a1 = 2 * kPi * (k + 1) / segments;
    const Vec3 b0{radius * std::cos(a0), radius * std::sin(a0), z0};
    const Vec3 b1{radius * std::cos(a1), radius * std::sin(a1), z0};
    const Vec3 t0{b0.x, b0.y, z1}, t1{b1.x, b1.y, z1};
    tris.push_back(Triangle{{b0, b1, t1}});
    tris.push_back(Triangle{{b0, t1, t0}});
  }
  return tris;
}

// The contacts a sphere touching the mesh for the first time makes (no earlier contacts).
std::vector<MeshContact> contacts_of(const Vec3& x, double r, const TriMesh& mesh) {
  std::vector<dem::TriRef> refs;
  for (std::uint32_t t = 0; t < mesh.size(); ++t) refs.push_back({0, t});
  std::vector<MeshContact> out;
  find_mesh_contacts(x, r, refs.data(), static_cast<int>(refs.size()), {&mesh}, out);
  std::vector<double> slots(dem::kMeshSlots * dem::kMeshSlotWidth, 0.0);
  std::vector<double*> hist;
  std::vector<double> overflow(64 * dem::kHistorySize);
  dem::assign_history_slots(slots.data(), out, {&mesh}, hist, overflow.data());
  return out;
}

std::unique_ptr<dem::Simulation> make_simulation() {
  dem::EngineOptions options;
  options.log_file = "none";
  options.progress = false;
  auto sim = std::make_unique<dem::Simulation>(options);
  for (const std::string line :
       {"units si", "atom_style granular", "boundary f f f",
        "region box block -1 1 -1 1 -1 1 units box", "create_box 2 box",
        "fix m1 all property/global youngsModulus peratomtype 5e6 5e6",
        "fix m2 all property/global poissonsRatio peratomtype 0.3 0.3",
        "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
        "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5",
        "pair_style gran model hertz tangential history", "pair_coeff * *"})
    sim->input().run_line(line, {"test", 0});
  return sim;
}

void deck(dem::Simulation& sim, const std::string& line) {
  sim.input().run_line(line, {"test", 1});
}

bool same_vec(const Vec3& a, const Vec3& b, double tol) { return norm(a - b) <= tol; }

}  // namespace

// --- STL files ---------------------------------------------------------------------------------

TEST_CASE("mesh: STL ASCII round trip is exact") {
  TempDir dir;
  std::vector<Triangle> tris = cylinder_mesh(0.0123456789, -0.1, 0.3, 12);
  const std::string path = dir.file("cyl.stl");
  dem::write_stl_ascii(path, tris, "cylinder");
  const auto back = dem::read_stl(path);
  CHECK_EQ(back.size(), tris.size());
  bool exact = back.size() == tris.size();
  for (std::size_t t = 0; exact && t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k)
      exact = exact && back[t].v[k].x == tris[t].v[k].x && back[t].v[k].y == tris[t].v[k].y &&
              back[t].v[k].z == tris[t].v[k].z;
  CHECK(exact);
}

TEST_CASE("mesh: STL binary round trip keeps 32-bit float values, also with a 'solid' header") {
  TempDir dir;
  std::vector<Triangle> tris = cylinder_mesh(0.0123456789, -0.1, 0.3, 12);
  const std::string path = dir.file("cyl.stl");
  dem::write_stl_binary(path, tris);
  CHECK_EQ(fs::file_size(path), static_cast<std::uintmax_t>(84 + 50 * tris.size()));
  auto back = dem::read_stl(path);
  CHECK_EQ(back.size(), tris.size());
  double worst = 0.0;
  bool float_exact = true;
  for (std::size_t t = 0; t < tris.size() && t < back.size(); ++t)
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        worst = std::max(worst, std::fabs(back[t].v[k][d] - tris[t].v[k][d]));
        float_exact = float_exact && back[t].v[k][d] == static_cast<float>(tris[t].v[k][d]);
      }
  CHECK(float_exact);
  CHECK(worst < 1e-7);
  // Binary files whose 80-byte header starts with "solid" are still binary (size rule).
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.write("solid fake", 10);
  }
  back = dem::read_stl(path);
  CHECK_EQ(back.size(), tris.size());
}

TEST_CASE("mesh: malformed STL files are errors naming the file and the line") {
  TempDir dir;
  const std::string bad = dir.file("bad.stl");
  write_text(bad,
             "solid s\n"
             "  facet normal 0 0 1\n"
             "    outer loop\n"
             "      vertex 0 0 0\n"
             "      vertex 1 0 zero\n"
             "      vertex 0 1 0\n"
             "    endloop\n"
             "  endfacet\n"
             "endsolid s\n");
  std::string msg = error_text([&] { dem::read_stl(bad); });
  CHECK(contains(msg, bad));
  CHECK(contains(msg, "line 5"));
  CHECK(contains(msg, "zero"));
  CHECK_THROWS_AS(dem::read_stl(bad), EngineError);

  const std::string two = dir.file("two_vertices.stl");
  write_text(two,
             "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
             "endfacet\nendsolid\n");
  msg = error_text([&] { dem::read_stl(two); });
  CHECK(contains(msg, "line 6"));
  CHECK(contains(msg, "vertex"));

  const std::string open = dir.file("truncated.stl");
  write_text(open, "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n");
  msg = error_text([&] { dem::read_stl(open); });
  CHECK(contains(msg, "line 4"));
  CHECK(contains(msg, "line 2"));  // where the unfinished facet starts

  const std::string junk = dir.file("junk.stl");
  write_text(junk, std::string(100, 'x'));
  msg = error_text([&] { dem::read_stl(junk); });
  CHECK(contains(msg, junk));
  CHECK(contains(msg, "100 bytes"));

  msg = error_text([&] { dem::read_stl(dir.file("missing.stl")); });
  CHECK(contains(msg, "cannot open"));
}

TEST_CASE("mesh: degenerate and duplicate triangles are rejected with their numbers") {
  std::vector<Triangle> tris = square_plate(1.0, 0.0);
  tris.push_back(Triangle{{Vec3{0, 0, 0}, Vec3{1, 1, 1}, Vec3{2, 2, 2}}});
  std::string msg = error_text([&] { TriMesh mesh(tris, "test mesh"); });
  CHECK(contains(msg, "triangle 3"));
  CHECK(contains(msg, "degenerate"));
  // The first facet again, with its vertices in another order.
  tris = square_plate(1.0, 0.0);
  tris.push_back(Triangle{{tris[0].v[2], tris[0].v[1], tris[0].v[0]}});
  msg = error_text([&] { TriMesh mesh(tris, "test mesh"); });
  CHECK(contains(msg, "triangles 1 and 3 are duplicates"));
}

TEST_CASE("mesh: ASCII STL with CRLF line ends and several solids") {
  TempDir dir;
  const std::string path = dir.file("crlf.stl");
  const std::string facet =
      "facet normal 0 0 1\r\nouter loop\r\nvertex 0 0 0\r\nvertex 1 0 0\r\n"
      "vertex 0 1 0.5\r\nendloop\r\nendfacet\r\n";
  write_text(path, "solid a\r\n" + facet + "endsolid a\r\nSOLID b\r\n" + facet +
                       "ENDSOLID b\r\n");
  const auto tris = dem::read_stl(path);
  CHECK_EQ(tris.size(), std::size_t{2});
  if (tris.size() == 2) CHECK(same_vec(tris[1].v[2], Vec3{0, 1, 0.5}, 0.0));
}

// --- triangle geometry -------------------------------------------------------------------------

TEST_CASE("mesh: closest point regions of a triangle") {
  const Vec3 a{0, 0, 0}, b{2, 0, 0}, c{0, 2, 0};
  struct Case {
    Vec3 p, expect;
    TriRegion region;
  };
  const Case cases[] = {
      {{0.5, 0.5, 3.0}, {0.5, 0.5, 0}, TriRegion::kFace},
      {{1.0, -1.0, 0.5}, {1.0, 0, 0}, TriRegion::kEdgeAB},
      {{-1.0, 1.0, -0.5}, {0, 1.0, 0}, TriRegion::kEdgeCA},
      {{2.0, 2.0, 0.0}, {1.0, 1.0, 0}, TriRegion::kEdgeBC},
      {{-1.0, -2.0, 1.0}, a, TriRegion::kVertexA},
      {{3.0, -0.5, 0.0}, b, TriRegion::kVertexB},
      {{-0.5, 3.0, 0.0}, c, TriRegion::kVertexC},
  };
  for (const Case& k : cases) {
    const ClosestPoint cp = dem::closest_point_on_triangle(k.p, a, b, c);
    CHECK(same_vec(cp.point, k.expect, 1e-14));
    CHECK(cp.region == k.region);
    // Barycentric weights reproduce the point.
    CHECK(same_vec(cp.wa * a + cp.wb * b + cp.wc * c, cp.point, 1e-14));
    CHECK_NEAR(cp.wa + cp.wb + cp.wc, 1.0, 1e-14);
  }
}

TEST_CASE("mesh: closest point equals a brute-force search on random triangles") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rv = [&] { return Vec3{u(rng), u(rng), u(rng)}; };
  int mismatches = 0, faces = 0, edges = 0, vertices = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 a = rv(), b = rv(), c = rv(), p = 1.5 * rv();
    if (dem::triangle_area(a, b, c) < 1e-3) continue;
    const ClosestPoint cp = dem::closest_point_on_triangle(p, a, b, c);
    const Vec3 ref = brute_closest(p, a, b, c);
    if (std::fabs(norm(cp.point - p) - norm(ref - p)) > 1e-12 || norm(cp.point - ref) > 1e-9)
      ++mismatches;
    if (cp.on_face()) ++faces;
    else if (cp.region == TriRegion::kVertexA || cp.region == TriRegion::kVertexB ||
             cp.region == TriRegion::kVertexC)
      ++vertices;
    else ++edges;
  }
  CHECK_EQ(mismatches, 0);
  CHECK(faces > 1000);  // every kind of region was exercised
  CHECK(edges > 1000);
  CHECK(vertices > 1000);
}

TEST_CASE("mesh: contact points from a kept plane; the plane cut drops no contact") {
  std::mt19937 rng(2718);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rv = [&] { return Vec3{u(rng), u(rng), u(rng)}; };
  int bad_weights = 0, bad_face = 0, dropped = 0, cut = 0, faces = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 a = rv(), b = rv(), c = rv(), p = 1.5 * rv();
    if (dem::triangle_area(a, b, c) < 1e-3) continue;
    const dem::TrianglePlane plane = dem::triangle_plane(a, b, c);
    const ClosestPoint cp = dem::contact_point_on_triangle(p, a, b, c, plane, 0.0);
    // The weights give the point, in every region.
    const Vec3 from_weights = cp.wa * a + cp.wb * b + cp.wc * c;
    if (norm(from_weights - cp.point) > 1e-12) ++bad_weights;
    // On the face the contact point is the closest point of the triangle.
    if (cp.on_face()) {
      ++faces;
      if (norm(dem::closest_point_on_triangle(p, a, b, c).point - cp.point) > 1e-12) ++bad_face;
    }
    // A sphere whose plane distance is at least its radius touches no point of the triangle.
    const double r = 0.5 * (u(rng) + 1.0);
    const double s = dot(p - a, plane.n);
    if (s * s >= r * r * plane.area2) {
      ++cut;
      if (norm(p - brute_closest(p, a, b, c)) < r * (1.0 - 1e-12)) ++dropped;
    }
  }
  CHECK_EQ(bad_weights, 0);
  CHECK_EQ(bad_face, 0);
  CHECK_EQ(dropped, 0);
  CHECK(faces > 1000);
  CHECK(cut > 1000);
}

TEST_CASE("mesh: the planes kept by a mesh are those of its nodes after every motion") {
  TriMesh tube(cylinder_mesh(0.5, 0.0, 1.0, 12), "tube");
  auto planes_match = [&] {
    int off = 0;
    for (std::size_t t = 0; t < tube.size(); ++t) {
      const dem::TrianglePlane fresh =
          dem::triangle_plane(tube.node(t, 0), tube.node(t, 1), tube.node(t, 2));
      const dem::TrianglePlane& kept = tube.plane(t);
      // Bit for bit: the kept plane is recomputed from the moved nodes, not carried along.
      if (!(kept.n.x == fresh.n.x && kept.n.y == fresh.n.y && kept.n.z == fresh.n.z &&
            kept.area2 == fresh.area2 && kept.grad[2].x == fresh.grad[2].x))
        ++off;
    }
    return off;
  };
  CHECK_EQ(planes_match(), 0);
  tube.translate(Vec3{0.1, -0.2, 0.3});
  CHECK_EQ(planes_match(), 0);
  tube.rotate(Vec3{0.0, 0.6, 0.8}, 0.7, Vec3{0.2, 0.0, 0.0});
  CHECK_EQ(planes_match(), 0);
  tube.scale(2.5);
  CHECK_EQ(planes_match(), 0);
}

// --- contacts: active edges and corners, coplanar patches (LIGGGHTS rules) ---------------------

TEST_CASE("mesh: a sphere on two coplanar triangles has one contact") {
  const TriMesh plate(square_plate(1.0, 0.0), "plate");
  const double r = 0.1;
  // Centre right above the diagonal: both faces, the second a coplanar neighbour of the first.
  auto c = contacts_of(Vec3{0.3, 0.3, 0.09}, r, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(c[0].tri, 0u);
  CHECK(same_vec(c[0].normal, Vec3{0, 0, 1}, 1e-12));
  CHECK_NEAR(c[0].dist, 0.09, 1e-14);
  // Slightly off the diagonal: the face of one triangle; the diagonal is an inactive edge.
  c = contacts_of(Vec3{0.31, 0.3, 0.09}, r, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK(c[0].cp.on_face());
  CHECK_EQ(c[0].tri, 0u);
  c = contacts_of(Vec3{0.3, 0.31, 0.09}, r, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(c[0].tri, 1u);
  // Beyond the shared corner (-1,-1): one contact, on the boundary edge of triangle 0.
  c = contacts_of(Vec3{-1.05, -1.05, 0.02}, r, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK(same_vec(c[0].cp.point, Vec3{-1, -1, 0}, 1e-14));
  // Beyond the middle of a boundary edge: the edge.
  c = contacts_of(Vec3{1.05, 0.2, 0.02}, r, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK(same_vec(c[0].cp.point, Vec3{1, 0.2, 0}, 1e-14));
}

TEST_CASE("mesh: a convex edge belongs to the later triangle, a concave corner gets both faces") {
  // Roof: two faces meeting at the ridge x = 0, z = 0, sloping down at 45 degrees; the ridge is
  // shared by triangles 0 and 2 and active in triangle 2 only.
  const std::vector<Triangle> roof = {
      Triangle{{Vec3{0, -1, 0}, Vec3{-1, -1, -1}, Vec3{0, 1, 0}}},
      Triangle{{Vec3{-1, -1, -1}, Vec3{-1, 1, -1}, Vec3{0, 1, 0}}},
      Triangle{{Vec3{0, -1, 0}, Vec3{0, 1, 0}, Vec3{1, -1, -1}}},
      Triangle{{Vec3{1, -1, -1}, Vec3{0, 1, 0}, Vec3{1, 1, -1}}},
  };
  const TriMesh ridge(roof, "roof");
  CHECK(!ridge.topology().edge_active(0, 2));
  CHECK(ridge.topology().edge_active(2, 0));
  auto c = contacts_of(Vec3{0.0, 0.2, 0.08}, 0.1, ridge);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(c[0].tri, 2u);
  CHECK(same_vec(c[0].normal, Vec3{0, 0, 1}, 1e-12));
  // Near the ridge on the left slope: its face, and the ridge of triangle 2 as well, which the
  // sphere overlaps (LIGGGHTS counts both).
  c = contacts_of(Vec3{-0.05, 0.2, 0.0}, 0.1, ridge);
  CHECK_EQ(c.size(), std::size_t{2});
  CHECK(c[0].cp.on_face());
  CHECK_EQ(c[1].tri, 2u);
  // Near the ridge on the right slope: only its face (the left triangle's ridge is inactive).
  c = contacts_of(Vec3{0.05, 0.2, 0.0}, 0.1, ridge);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK(c[0].cp.on_face());

  // Valley (the roof upside down): a sphere in the groove touches both faces.
  std::vector<Triangle> valley = roof;
  for (Triangle& t : valley)
    for (Vec3& v : t.v) v.z = -v.z;
  const TriMesh groove(valley, "valley");
  c = contacts_of(Vec3{0.0, 0.2, 0.13}, 0.1, groove);
  CHECK_EQ(c.size(), std::size_t{2});
  for (const auto& k : c) CHECK(k.cp.on_face());
  // With a curvature above the 90 degree bend... not allowed: it exceeds the triangle angles.
  TriMesh bent = groove;
  CHECK_THROWS_AS(bent.set_curvature(59.0, "valley"), EngineError);
}

TEST_CASE("mesh: faces bent less than the curvature are one surface") {
  // Two panels bent by 10 degrees at x = 0, each of two triangles.
  const double s = std::sin(10 * kPi / 180), cz = std::cos(10 * kPi / 180);
  const std::vector<Triangle> bent = {
      Triangle{{Vec3{-1, -1, 0}, Vec3{0, -1, 0}, Vec3{0, 1, 0}}},
      Triangle{{Vec3{-1, -1, 0}, Vec3{0, 1, 0}, Vec3{-1, 1, 0}}},
      Triangle{{Vec3{0, -1, 0}, Vec3{cz, -1, s}, Vec3{cz, 1, s}}},
      Triangle{{Vec3{0, -1, 0}, Vec3{cz, 1, s}, Vec3{0, 1, 0}}},
  };
  TriMesh mesh(bent, "bent");
  // A sphere in the concave bend touches both panels ...
  const Vec3 x{0.0, 0.3, 0.098};
  CHECK_EQ(contacts_of(x, 0.1, mesh).size(), std::size_t{2});
  CHECK(!mesh.topology().coplanar_neighbours(0, 3));
  // ... but once with a curvature of 20 degrees (the later panel is skipped).
  mesh.set_curvature(20.0, "bent");
  CHECK(mesh.topology().coplanar_neighbours(0, 3));
  const auto c = contacts_of(x, 0.1, mesh);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(c[0].tri, 0u);
}

TEST_CASE("mesh: a vertex shared by a fan of triangles gives one contact") {
  std::vector<Triangle> fan;
  const int n = 7;
  for (int k = 0; k < n; ++k) {
    const double a0 = 2 * kPi * k / n, a1 = 2 * kPi * (k + 1) / n;
    // A shallow cone: the apex is a convex vertex.
    fan.push_back(Triangle{{Vec3{0, 0, 0}, Vec3{std::cos(a0), std::sin(a0), -0.3},
                            Vec3{std::cos(a1), std::sin(a1), -0.3}}});
  }
  const TriMesh cone(fan, "cone");
  const auto c = contacts_of(Vec3{0, 0, 0.05}, 0.1, cone);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK(same_vec(c[0].cp.point, Vec3{0, 0, 0}, 1e-14));
}

TEST_CASE("mesh: triangles sharing only a vertex both touch a sphere at it") {
  // A bow tie: two triangles meeting at the origin, not coplanar.
  const std::vector<Triangle> tie = {
      Triangle{{Vec3{0, 0, 0}, Vec3{-4, -1, 0}, Vec3{-4, 1, 0}}},
      Triangle{{Vec3{0, 0, 0}, Vec3{4, 1, -1}, Vec3{4, -1, -1}}},
  };
  const TriMesh mesh(tie, "tie");
  CHECK_EQ(contacts_of(Vec3{0.05, 0.01, 0.9}, 1.0, mesh).size(), std::size_t{2});
}

// --- contact history slots ---------------------------------------------------------------------

TEST_CASE("mesh: history persists, moves across a flat edge and is released when it opens") {
  const TriMesh plate(square_plate(1.0, 0.0), "plate");
  const std::vector<const TriMesh*> meshes = {&plate};
  std::vector<double> slots(dem::kMeshSlots * dem::kMeshSlotWidth, 0.0);
  std::vector<double*> hist;
  std::vector<double> overflow(64 * dem::kHistorySize);
  auto c = contacts_of(Vec3{0.5, 0.2, 0.09}, 0.1, plate);  // face of triangle 0
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data()), 0);
  CHECK_EQ(hist[0][0], 0.0);
  hist[0][0] = 1.5e-6;  // a tangential spring
  hist[0][5] = -2.0;
  // Next step, same triangle: same history.
  dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
  CHECK_EQ(hist[0][0], 1.5e-6);
  // Rolled across the diagonal onto triangle 1: the history follows.
  c = contacts_of(Vec3{0.2, 0.5, 0.09}, 0.1, plate);
  CHECK_EQ(c.size(), std::size_t{1});
  CHECK_EQ(c[0].tri, 1u);
  dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
  CHECK_EQ(hist[0][0], 1.5e-6);
  CHECK_EQ(hist[0][5], -2.0);
  // Lifted off: all slots are released; touching again starts from zero.
  c.clear();
  dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
  CHECK(std::all_of(slots.begin(), slots.end(), [](double v) { return v == 0.0; }));
  c = contacts_of(Vec3{0.2, 0.5, 0.09}, 0.1, plate);
  dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
  CHECK_EQ(hist[0][0], 0.0);
}

TEST_CASE("mesh: history does not move between faces bent more than the curvature") {
  // Two panels at 10 degrees; curvature 5 degrees keeps them apart, 20 degrees joins them.
  const double s = std::sin(10 * kPi / 180), cz = std::cos(10 * kPi / 180);
  const std::vector<Triangle> bent = {
      Triangle{{Vec3{-1, -1, 0}, Vec3{0, -1, 0}, Vec3{0, 1, 0}}},
      Triangle{{Vec3{-1, -1, 0}, Vec3{0, 1, 0}, Vec3{-1, 1, 0}}},
      Triangle{{Vec3{0, -1, 0}, Vec3{cz, -1, s}, Vec3{cz, 1, s}}},
      Triangle{{Vec3{0, -1, 0}, Vec3{cz, 1, s}, Vec3{0, 1, 0}}},
  };
  for (const double curvature : {5.0, 20.0}) {
    TriMesh mesh(bent, "bent");
    mesh.set_curvature(curvature, "bent");
    const std::vector<const TriMesh*> meshes = {&mesh};
    std::vector<double> slots(dem::kMeshSlots * dem::kMeshSlotWidth, 0.0);
    std::vector<double*> hist;
    std::vector<double> overflow(64 * dem::kHistorySize);
    auto c = contacts_of(Vec3{-0.3, 0.0, 0.09}, 0.1, mesh);
    CHECK_EQ(c.size(), std::size_t{1});
    CHECK_EQ(c[0].tri, 0u);
    dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
    hist[0][1] = 7.0;
    // On triangle 3, which shares the bend edge with triangle 0.
    const Vec3 n2{-s, 0, cz};
    c = contacts_of(Vec3{0.5 * cz, 0.5, 0.5 * s} + 0.09 * n2, 0.1, mesh);
    CHECK_EQ(c.size(), std::size_t{1});
    CHECK_EQ(c[0].tri, 3u);
    dem::assign_history_slots(slots.data(), c, meshes, hist, overflow.data());
    CHECK_EQ(hist[0][1], curvature > 10.0 ? 7.0 : 0.0);
  }
}

TEST_CASE("mesh: the live-slot record follows the keys through overflow and release") {
  // A sphere on the axis of a 12-sided tube slightly narrower than it touches 12 faces (two
  // coplanar triangles each): more contacts than slots.
  const TriMesh tube(cylinder_mesh(0.0099, -0.02, 0.02, 12), "tube");
  const std::vector<const TriMesh*> meshes = {&tube};
  std::vector<dem::TriRef> refs;
  for (std::uint32_t t = 0; t < tube.size(); ++t) refs.push_back({0, t});
  std::vector<double> slots(dem::kMeshSlots * dem::kMeshSlotWidth, 0.0);
  std::vector<double*> hist;
  std::vector<double> overflow(64 * dem::kHistorySize);
  std::uint32_t live = 0;
  std::vector<MeshContact> c;
  const Vec3 path[] = {{0, 0, 0}, {0, 0, 0.001}, {0.0001, 0, 0}, {0.003, 0.002, 0},
                       {0.009, 0, 0}, {0, 0, 0}, {0, 0.0096, 0}, {0, 0, 0.0005}};
  int overflowed = 0;
  for (const Vec3& x : path) {
    find_mesh_contacts(x, 0.01, refs.data(), static_cast<int>(refs.size()), meshes, c);
    overflowed += dem::assign_history_slots(slots.data(), live, c, meshes, hist, overflow.data());
    CHECK_EQ(live, dem::live_slots(slots.data()));
    for (double* h : hist) h[0] += 1.0;  // the contacts' springs
  }
  CHECK(overflowed > 0);
  // Released slots are all zeros, and the record is empty.
  dem::release_slots(slots.data(), live);
  CHECK_EQ(live, 0u);
  CHECK(std::all_of(slots.begin(), slots.end(), [](double v) { return v == 0.0; }));
}

TEST_CASE("mesh: wall/gran keeps its live-slot record through opening contacts and resorting") {
  TempDir dir;
  const std::string stl = dir.file("plate.stl");
  dem::write_stl_ascii(stl, square_plate(0.01, 0.0));
  auto sim = make_simulation();
  // No integration: the particles stay put while the plate sinks by 1e-6 m a step (a contact
  // opens when the plate has sunk by its overlap; the triangle list is rebuilt every 10 steps).
  for (const std::string& line : std::vector<std::string>{
           "neighbor 0.00002 bin", "timestep 1e-5",
           "fix plate all mesh/surface file " + stl + " type 1",
           "fix w all wall/gran model hertz tangential history mesh n_meshes 1 meshes plate",
           "fix sink all move/mesh mesh plate linear 0 0 -0.1",
           "create_atoms 1 single 0 0 0.0004 units box",             // overlap 1e-4
           "create_atoms 1 single 0.003 0 0.00049 units box",        // overlap 1e-5
           "create_atoms 1 single -0.003 0.003 0.00051 units box",   // within the skin, apart
           "create_atoms 1 single 0.005 -0.005 0.00042 units box",   // overlap 8e-5
           "create_atoms 1 single -0.006 -0.004 0.0004 units box",   // overlap 1e-4
           "set group all diameter 0.001 density 2500"})
    deck(*sim, line);
  dem::Particles& p = sim->atoms;
  // The handles of the fix's extras (registering a name again returns its handle).
  const std::size_t slots_h = p.register_extra("wall/gran:w:mesh", 0);
  const std::size_t live_h = p.register_extra("wall/gran:w:mesh_live", 0);
  auto live_of = [&](std::int64_t tag) {
    const long i = p.index_of(tag);
    CHECK(i >= 0);
    return i >= 0 ? p.extra(live_h)[static_cast<std::size_t>(i)] : -1.0;
  };
  auto check_records = [&] {
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double* slots = p.extra(slots_h).data() + i * dem::kMeshSlots * dem::kMeshSlotWidth;
      CHECK_EQ(p.extra(live_h)[i], static_cast<double>(dem::live_slots(slots)));
      if (p.extra(live_h)[i] == 0.0)
        CHECK(std::all_of(slots, slots + dem::kMeshSlots * dem::kMeshSlotWidth,
                          [](double v) { return v == 0.0; }));
    }
  };
  deck(*sim, "run 2");
  check_records();
  CHECK(live_of(1) != 0.0 && live_of(2) != 0.0 && live_of(4) != 0.0);
  CHECK_EQ(live_of(3), 0.0);
  deck(*sim, "run 20");  // particle 2's contact has opened; the list was rebuilt twice
  check_records();
  CHECK_EQ(live_of(2), 0.0);
  CHECK(live_of(1) != 0.0 && live_of(4) != 0.0);
  // Deleted and reordered particles take their records along.
  deck(*sim, "region gone block 0.004 0.006 -0.006 -0.004 -0.001 0.001 units box");
  deck(*sim, "delete_atoms region gone compress no");
  CHECK_EQ(p.index_of(4), -1L);
  std::vector<std::size_t> reversed(p.size());
  for (std::size_t k = 0; k < reversed.size(); ++k) reversed[k] = reversed.size() - 1 - k;
  p.permute(reversed);
  check_records();
  CHECK(live_of(1) != 0.0 && live_of(5) != 0.0);
  deck(*sim, "create_atoms 1 single 0.0 0.005 0.00043 units box");  // a newcomer touching
  deck(*sim, "set atom 6 diameter 0.001 density 2500");
  deck(*sim, "run 3");
  check_records();
  CHECK(live_of(6) != 0.0 && live_of(1) != 0.0);
  deck(*sim, "run 200");  // every contact has opened
  check_records();
  for (std::size_t i = 0; i < p.size(); ++i) CHECK_EQ(p.extra(live_h)[i], 0.0);
}

// --- candidate search --------------------------------------------------------------------------

TEST_CASE("mesh: triangle candidates of 8000 particles in a 256-triangle cylinder") {
  const double rc = 0.02, r = 0.0005, skin = 0.0002;
  const TriMesh cyl(cylinder_mesh(rc, 0.0, 0.03, 128), "cylinder");
  CHECK_EQ(cyl.size(), std::size_t{256});
  dem::Particles p;
  const double h = 0.00163;
  for (double z = r; z < 0.03 - r && p.size() < 8000; z += h)
    for (double y = -rc; y < rc && p.size() < 8000; y += h)
      for (double x = -rc; x < rc && p.size() < 8000; x += h)
        if (x * x + y * y < (rc - 0.8 * r) * (rc - 0.8 * r))
          p.add(p.next_tag(), 1, 1u, Vec3{x, y, z}, r, 2500.0);
  CHECK_EQ(p.size(), std::size_t{8000});
  dem::TriangleNeighborList list;
  const std::vector<const TriMesh*> meshes = {&cyl};
  list.build(p, 1u, meshes, skin);
  // Far fewer exact distance tests than all 2 048 000 particle-triangle pairs.
  CHECK(list.last_build_checks() < 100000);
  // Exactly the pairs closer than r + skin (brute force over all pairs).
  long missing = 0, extra = 0, total = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::set<std::uint32_t> want, got;
    for (std::uint32_t t = 0; t < cyl.size(); ++t)
      if (norm(cyl.closest_point(t, p.x[i]).point - p.x[i]) < r + skin) want.insert(t);
    for (int k = list.first[i]; k < list.first[i + 1]; ++k) got.insert(list.refs[k].tri);
    for (auto t : want) missing += got.count(t) == 0;
    for (auto t : got) extra += want.count(t) == 0;
    total += static_cast<long>(got.size());
  }
  CHECK_EQ(missing, 0L);
  CHECK_EQ(extra, 0L);
  CHECK(total > 100);  // the outer particles do have candidates
  // Valid while everything moved less than skin/2; due after more.
  CHECK(!list.due(p, meshes));
  for (auto& x : p.x) x.x += 0.4 * skin;
  CHECK(!list.due(p, meshes));
  p.x[17].y += 0.35 * skin;
  CHECK(list.due(p, meshes));
  for (auto& x : p.x) x.x -= 0.4 * skin;
  p.x[17].y -= 0.35 * skin;
  TriMesh moved = cyl;
  const std::vector<const TriMesh*> moved_meshes = {&moved};
  list.build(p, 1u, moved_meshes, skin);
  moved.translate(Vec3{0, 0, 0.45 * skin});
  CHECK(!list.due(p, moved_meshes));
  moved.translate(Vec3{0, 0, 0.1 * skin});
  CHECK(list.due(p, moved_meshes));
  // Removing a particle changes the storage: due.
  list.build(p, 1u, moved_meshes, skin);
  std::vector<char> flag(p.size(), 0);
  flag[3] = 1;
  p.remove(flag);
  CHECK(list.due(p, moved_meshes));
}

namespace {

// Bit for bit equal contact lists (field by field: MeshContact has padding).
bool same_contacts(const std::vector<MeshContact>& a, const std::vector<MeshContact>& b) {
  if (a.size() != b.size()) return false;
  auto same = [](const Vec3& u, const Vec3& v) { return u.x == v.x && u.y == v.y && u.z == v.z; };
  for (std::size_t k = 0; k < a.size(); ++k) {
    const MeshContact &c = a[k], &d = b[k];
    if (c.mesh != d.mesh || c.tri != d.tri || !same(c.cp.point, d.cp.point) ||
        c.cp.wa != d.cp.wa || c.cp.wb != d.cp.wb || c.cp.wc != d.cp.wc ||
        c.cp.region != d.cp.region || !same(c.normal, d.normal) || c.dist != d.dist)
      return false;
  }
  return true;
}

}  // namespace

TEST_CASE("mesh: candidates passed over by the motion bound are out of reach") {
  // A coarse tube (facets bent by 30 degrees, so edges and corners act) and a plate closing it
  // at the bottom, both moving; particles near the wall, each step displaced anew from its
  // position at the build by up to 0.45 skin. Every candidate's contact distance at the step
  // is at least its bound at the build less both motions, and the contacts found with the
  // bound are those found without it, bit for bit and in order, also for radii that put a
  // candidate just within reach.
  const double rc = 0.01, r = 0.001, skin = 0.0008;
  TriMesh tube(cylinder_mesh(rc, 0.0, 0.02, 12), "tube");
  TriMesh floor(square_plate(rc, 0.0), "floor");
  const std::vector<const TriMesh*> meshes = {&tube, &floor};
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto ball = [&](double radius) {  // uniform in a ball
    Vec3 v;
    do v = Vec3{2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1};
    while (norm2(v) > 1.0);
    return radius * v;
  };
  dem::Particles p;
  for (int k = 0; k < 300; ++k) {
    const double phi = 2 * kPi * u(rng), rho = rc - (r + skin) * 1.2 * u(rng);
    const double z = k % 3 == 0 ? (r + skin) * 1.2 * u(rng) : 0.02 * u(rng);
    p.add(p.next_tag(), 1, 1u, Vec3{rho * std::cos(phi), rho * std::sin(phi), z},
          r * (0.5 + 0.5 * u(rng)), 2500.0);
  }
  dem::TriangleNeighborList list;
  list.build(p, 1u, meshes, skin);
  std::vector<Vec3> x_build = p.x;
  const std::vector<double> radius = p.radius;
  long candidates = 0, passed_over = 0, below_bound = 0, differing = 0, contacts = 0, edges = 0;
  long rebuilds = 0;
  std::vector<MeshContact> with, without;
  for (int step = 0; step < 40; ++step) {
    for (std::size_t i = 0; i < p.size(); ++i) p.x[i] = x_build[i] + ball(0.45 * skin);
    // The meshes turn and slide a little further at every step (rebuilt when due).
    tube.rotate(Vec3{0.0, 0.0, 1.0}, 0.004, Vec3{0.0, 0.0, 0.0});
    floor.translate(Vec3{0.00001, -0.00002, 0.00001});
    if (list.due(p, meshes)) {
      list.build(p, 1u, meshes, skin);
      x_build = p.x;
      ++rebuilds;
      continue;
    }
    // The motions the list measured on the way.
    CHECK_EQ(list.moved2(7), norm2(p.x[7] - x_build[7]));
    for (std::size_t i = 0; i < p.size(); ++i) {
      const int first = list.first[i], n = list.first[i + 1] - first;
      const double moved = std::sqrt(list.moved2(i));
      for (int k = first; k < first + n; ++k) {
        const dem::TriRef ref = list.refs[k];
        const TriMesh& mesh = *meshes[ref.mesh];
        const double now = norm(p.x[i] - mesh.contact_point(ref.tri, p.x[i]).point);
        const double bound = list.dist[k] - moved - list.mesh_shift()[ref.mesh];
        ++candidates;
        if (now < bound - 1e-9 * r) ++below_bound;
        if (bound > (1.0 + 1e-6) * p.radius[i]) ++passed_over;
      }
      // At its own radius, then at radii just above and at the contact distance of each
      // candidate (the bound must let the one just within reach through).
      std::vector<double> radii = {p.radius[i]};
      for (int k = first; k < first + n; ++k) {
        const TriMesh& mesh = *meshes[list.refs[k].mesh];
        const double d = norm(p.x[i] - mesh.contact_point(list.refs[k].tri, p.x[i]).point);
        radii.push_back(d);
        radii.push_back(std::nextafter(d, 1.0));
      }
      const dem::CandidateMotion motion{list.dist.data() + first, moved,
                                        list.mesh_shift().data()};
      for (double ri : radii) {
        dem::find_mesh_contacts(p.x[i], ri, list.refs.data() + first, n, meshes, with, motion);
        dem::find_mesh_contacts(p.x[i], ri, list.refs.data() + first, n, meshes, without);
        if (!same_contacts(with, without)) ++differing;
        contacts += static_cast<long>(without.size());
        for (const MeshContact& c : without) edges += !c.cp.on_face();
      }
    }
    p.radius = radius;
  }
  CHECK_EQ(below_bound, 0L);
  CHECK_EQ(differing, 0L);
  CHECK(rebuilds >= 1 && rebuilds < 20);  // the bound served many steps, not only builds
  CHECK(passed_over > candidates / 10);   // it does pass over candidates
  CHECK(contacts > 10000);
  CHECK(edges > 1000);  // edge and corner contacts too, not only faces
  // A particle that has not moved and a mesh that has not moved since the build: zero motion.
  list.build(p, 1u, meshes, skin);
  CHECK(!list.due(p, meshes));
  CHECK_EQ(list.moved2(3), 0.0);
  CHECK_EQ(list.mesh_shift()[0], 0.0);
  const Vec3 shift{0.0001, 0.0, 0.0002};
  floor.translate(shift);
  CHECK(!list.due(p, meshes));
  CHECK_NEAR(list.mesh_shift()[1], norm(shift), 1e-15);
  CHECK_EQ(list.mesh_shift()[0], 0.0);
}

TEST_CASE("mesh: the motion bound keeps a centre within the face tolerance beyond an edge") {
  // The centre lies in the plane, just beyond a boundary edge but within the face tolerance:
  // LIGGGHTS' contact point is the centre itself (distance 0), while the triangle is a few
  // nanometres away. A sphere of 1 nm radius touches; the bound must not pass it over.
  const TriMesh plate(square_plate(1.0, 0.0), "plate");
  const std::vector<const TriMesh*> meshes = {&plate};
  // Triangle 0 is (-1,-1,0), (1,-1,0), (1,1,0): its edge y = -1 is a boundary edge, and node
  // (1,1,0) stands 2 above it, so the centre's weight of that node is -beyond / 2.
  const double beyond = plate.topology().face_tolerance(0);
  dem::Particles p;
  p.add(p.next_tag(), 1, 1u, Vec3{0.5, -1.0 - beyond, 0.0}, 1e-9, 2500.0);
  dem::TriangleNeighborList list;
  list.build(p, 1u, meshes, 0.001);
  CHECK(!list.due(p, meshes));
  const int n = list.first[1] - list.first[0];
  CHECK(n >= 1);
  std::vector<MeshContact> with, without;
  dem::find_mesh_contacts(p.x[0], p.radius[0], list.refs.data(), n, meshes, without);
  dem::find_mesh_contacts(p.x[0], p.radius[0], list.refs.data(), n, meshes, with,
                          {list.dist.data(), std::sqrt(list.moved2(0)), list.mesh_shift().data()});
  CHECK_EQ(without.size(), std::size_t{1});
  CHECK(same_contacts(with, without));
  if (!without.empty()) {
    CHECK_EQ(without[0].tri, 0u);
    CHECK(without[0].cp.on_face());
    CHECK_EQ(without[0].dist, 0.0);
  }
}

// --- meshes, motions, primitives, servo ---------------------------------------------------------

TEST_CASE("mesh: rigid motions and frames carried by earlier motions") {
  TriMesh mesh(square_plate(1.0, 0.0), "plate");
  const std::size_t f0 = mesh.add_frame(Vec3{0, 0, 0}, Vec3{0, 0, 1});
  const std::size_t f1 = mesh.add_frame(Vec3{1, 0, 0}, Vec3{0, 0, 1});
  // The first motion rotates by 90 degrees about z through the origin: frame 1 goes along.
  mesh.rotate(Vec3{0, 0, 1}, 0.5 * kPi, mesh.frame(f0).origin, f0);
  CHECK(same_vec(mesh.frame(f1).origin, Vec3{0, 1, 0}, 1e-15));
  CHECK(same_vec(mesh.node(0, 1), Vec3{1, 1, 0}, 1e-15));  // (1,-1,0) rotated
  // The second motion translates; it does not move the frame of the first one.
  mesh.translate(Vec3{0, 0, 2}, f1);
  CHECK(same_vec(mesh.frame(f0).origin, Vec3{0, 0, 0}, 1e-15));
  CHECK(same_vec(mesh.frame(f1).origin, Vec3{0, 1, 2}, 1e-15));
  // Rotation velocities are interpolated exactly inside a triangle.
  mesh.clear_velocities();
  mesh.add_rotation_velocity(Vec3{0, 0, 3}, Vec3{0, 0, 0});
  const Vec3 p{0.2, 0.1, 5.0};
  const ClosestPoint cp = mesh.closest_point(0, p);
  CHECK(same_vec(mesh.velocity_at(0, cp), cross(Vec3{0, 0, 3}, cp.point), 1e-14));
  CHECK_NEAR(mesh.max_node_speed(), 3.0 * std::sqrt(2.0), 1e-14);
}

TEST_CASE("mesh: primitive planes and cylinders act from the side of the centre") {
  std::vector<std::string> w = {"zplane", "0.5", "ycylinder", "2", "3", "1"};
  std::size_t pos = 0;
  const auto plane = dem::PrimitiveWall::parse(w, pos);
  CHECK_EQ(pos, std::size_t{2});
  const auto cyl = dem::PrimitiveWall::parse(w, pos);
  CHECK_EQ(pos, std::size_t{6});
  Vec3 n;
  double d = 0;
  CHECK(plane.contact(Vec3{9, 9, 0.6}, 0.2, n, d));
  CHECK(same_vec(n, Vec3{0, 0, 1}, 0));
  CHECK_NEAR(d, 0.1, 1e-15);
  CHECK(plane.contact(Vec3{9, 9, 0.45}, 0.2, n, d));
  CHECK(same_vec(n, Vec3{0, 0, -1}, 0));
  CHECK(!plane.contact(Vec3{0, 0, 0.8}, 0.2, n, d));
  // ycylinder radius 2 about z = 3, x = 1 (LIGGGHTS order: z, then x): inside pushes towards
  // the axis, outside away.
  CHECK(cyl.contact(Vec3{2.9, 7, 3}, 0.2, n, d));
  CHECK(same_vec(n, Vec3{-1, 0, 0}, 1e-15));
  CHECK_NEAR(d, 0.1, 1e-12);
  CHECK(cyl.contact(Vec3{1, -4, 5.1}, 0.2, n, d));
  CHECK(same_vec(n, Vec3{0, 0, 1}, 1e-15));
  CHECK(!cyl.contact(Vec3{1, 0, 3.5}, 0.2, n, d));
  std::vector<std::string> bad = {"zcylinder", "-1", "0", "0"};
  pos = 0;
  CHECK_THROWS_AS(dem::PrimitiveWall::parse(bad, pos), EngineError);
}

TEST_CASE("mesh: servo law drives a spring-loaded lid to its target force") {
  // Lid on a bed that pushes back with k (z_bed - z) when compressed; axis +z.
  const double k = 1e4, z_bed = 0.0, target = -10.0, dt = 1e-5;
  for (const double ki : {0.0, 500.0}) {
    dem::ServoController servo;
    servo.vel_max = 0.1;
    servo.kp = 5.0;
    servo.ki = ki;
    servo.set_target(target);
    double z = 0.002, v = 0.0, f_max = 0.0, f = 0.0;
    for (int step = 0; step < 20000; ++step) {
      z += v * dt;
      f = z < z_bed ? k * (z_bed - z) : 0.0;  // force of the bed on the lid, along +z
      f_max = std::max(f_max, f);
      v = servo.update(f, dt);
      if (step == 0) CHECK_NEAR(v, -0.1, 1e-15);  // approaches at vel_max
    }
    CHECK_NEAR(f, 10.0, 1e-6);
    CHECK(f_max < 15.0);  // no wind-up overshoot after the saturated approach
  }
  // A positive target moves the wall along +axis while nothing pushes on it.
  dem::ServoController up;
  up.vel_max = 0.5;
  up.set_target(3.0);
  CHECK(up.update(0.0, 1e-5) > 0.0);
  CHECK_THROWS_AS(up.set_target(0.0), EngineError);
}

TEST_CASE("mesh: mesh/surface applies scale, move and rotate in the order given") {
  TempDir dir;
  const std::string stl = dir.file("tri.stl");
  dem::write_stl_ascii(stl, {Triangle{{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}}}});
  auto sim = make_simulation();
  deck(*sim, "fix a all mesh/surface file " + stl + " type 2 scale 2 move 1 0 0");
  deck(*sim, "fix b all mesh/surface file " + stl + " type 1 move 1 0 0 scale 2");
  deck(*sim,
       "fix c all mesh/surface file " + stl + " type 1 rotate axis 0 0 1 angle 90 move 0 0 1");
  deck(*sim, "fix d all mesh/surface/stress file " + stl +
                 " type 1 curvature 10 stress on reference_point 0 0 1");
  auto& a = dynamic_cast<dem::FixMeshSurface&>(sim->fix("a"));
  auto& b = dynamic_cast<dem::FixMeshSurface&>(sim->fix("b"));
  auto& c = dynamic_cast<dem::FixMeshSurface&>(sim->fix("c"));
  CHECK(same_vec(a.mesh().node(0, 0), Vec3{3, 0, 0}, 1e-15));
  CHECK(same_vec(a.mesh().node(0, 1), Vec3{1, 2, 0}, 1e-15));
  CHECK(same_vec(b.mesh().node(0, 0), Vec3{4, 0, 0}, 1e-15));
  CHECK(same_vec(b.mesh().node(0, 2), Vec3{2, 0, 2}, 1e-15));
  CHECK(same_vec(c.mesh().node(0, 0), Vec3{0, 1, 1}, 1e-12));
  CHECK(same_vec(c.mesh().node(0, 1), Vec3{-1, 0, 1}, 1e-12));
  CHECK_EQ(a.wall_type(), 2);
  CHECK_NEAR(sim->fix("d").vector(1), 0.0, 0.0);
  // Errors name the problem.
  const std::string head = "fix e all mesh/surface file ";
  std::string msg = error_text([&] { deck(*sim, head + stl + " type 3"); });
  CHECK(contains(msg, "type 3"));
  msg = error_text([&] { deck(*sim, head + stl + " scale 2 type 1"); });
  CHECK(contains(msg, "type"));
  msg = error_text([&] { deck(*sim, head + stl + " type 1 scale 2 curvature 5 move 1 0 0"); });
  CHECK(contains(msg, "wrong keyword order: move"));
  msg = error_text([&] { deck(*sim, head + stl + " type 1 heal no"); });
  CHECK(contains(msg, "heal"));
  msg = error_text([&] { deck(*sim, head + dir.file("none.stl") + " type 1"); });
  CHECK(contains(msg, "none.stl"));
  msg = error_text([&] {
    deck(*sim, "fix s all mesh/surface/stress/servo file " + stl +
                   " type 1 com 0 0 0 ctrlPV force axis 0 0 1 target_val -5");
  });
  CHECK(contains(msg, "vel_max"));
  msg = error_text([&] {
    deck(*sim, "fix w all wall/gran model hertz tangential history rolling_friction epsd2 "
               "mesh n_meshes 1 meshes a");
  });
  CHECK(contains(msg, "differs from the pair style"));
  msg = error_text([&] {
    deck(*sim, "fix w all wall/gran model hertz tangential history mesh n_meshes 2 meshes a m1");
  });
  CHECK(contains(msg, "m1"));
  deck(*sim, "fix w all wall/gran model hertz tangential history mesh n_meshes 2 meshes a b");
  deck(*sim, "fix mv all move/mesh mesh a rotate origin 0 0 0 axis 0 0 1 period 2");
  msg = error_text([&] { deck(*sim, "fix mv2 all move/mesh mesh a riggle origin 0 0 0"); });
  CHECK(contains(msg, "riggle"));
}

TEST_CASE("mesh: move/mesh rotate and superposed linear + rotate follow the closed form") {
  TempDir dir;
  const std::string stl = dir.file("plate.stl");
  dem::write_stl_ascii(stl, square_plate(0.01, 0.0));
  auto sim = make_simulation();
  deck(*sim, "timestep 0.001");
  deck(*sim, "fix spin all mesh/surface file " + stl + " type 1");
  deck(*sim, "fix rot all move/mesh mesh spin rotate origin 0.02 0 0 axis 0 0 2 period 0.4");
  // Second mesh: carried along x, and rotating about an origin that travels with it.
  deck(*sim, "fix both all mesh/surface file " + stl + " type 1");
  deck(*sim, "fix lin all move/mesh mesh both linear 0.5 0 0");
  deck(*sim, "fix rot2 all move/mesh mesh both rotate origin 0 0 0 axis 0 0 1 period 0.4");
  deck(*sim, "run 150");
  const double t = 0.15, omega = 2 * kPi / 0.4;
  auto& spin = dynamic_cast<dem::FixMeshSurface&>(sim->fix("spin")).mesh();
  auto& both = dynamic_cast<dem::FixMeshSurface&>(sim->fix("both")).mesh();
  const Vec3 corner{0.01, -0.01, 0.0};  // node 1 of triangle 0
  const Vec3 o1{0.02, 0, 0};
  const double cs = std::cos(omega * t), sn = std::sin(omega * t);
  const Vec3 expect1 = o1 + dem::rotate_about_axis(corner - o1, Vec3{0, 0, 1}, cs, sn);
  CHECK(same_vec(spin.node(0, 1), expect1, 1e-12));
  const Vec3 o2{0.5 * t, 0, 0};
  const Vec3 expect2 = o2 + dem::rotate_about_axis(corner, Vec3{0, 0, 1}, cs, sn);
  CHECK(same_vec(both.node(0, 1), expect2, 1e-12));
  // Node velocities: rotation about the (moving) origin plus the carrier velocity.
  const ClosestPoint at_node = both.closest_point(0, expect2 + Vec3{0, 0, 1});
  CHECK(same_vec(spin.velocity_at(0, spin.closest_point(0, expect1 + Vec3{0, 0, 1})),
                 cross(Vec3{0, 0, omega}, expect1 - o1), 1e-12));
  CHECK(same_vec(both.velocity_at(0, at_node),
                 Vec3{0.5, 0, 0} + cross(Vec3{0, 0, omega}, expect2 - o2), 1e-12));
  // The fastest node of the rotating plate sets the wall speed for the time-step check.
  const double rmax = norm(Vec3{0.03, 0.01, 0});
  CHECK_NEAR(sim->fix("rot").max_wall_speed(), omega * rmax, 1e-12);
}

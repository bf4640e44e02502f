#include "mesh/fix_wall_gran.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/numbers.h"
#include "core/simulation.h"
#include "core/threads.h"
#include "deck/errors.h"

namespace dem {

namespace {

bool same_spec(const ModelSpec& a, const ModelSpec& b) {
  return a.cohesion_sjkr == b.cohesion_sjkr && a.rolling_epsd2 == b.rolling_epsd2 &&
         a.options.limit_force == b.options.limit_force &&
         a.options.tangential_damping == b.options.tangential_damping &&
         a.options.tangential_reduce == b.options.tangential_reduce;
}

std::string describe(const ModelSpec& s) {
  std::string text = "model hertz tangential history";
  if (s.cohesion_sjkr) text += " cohesion sjkr";
  if (s.rolling_epsd2) text += " rolling_friction epsd2";
  if (s.options.limit_force) text += " limitForce on";
  if (!s.options.tangential_damping) text += " tangential_damping off";
  if (s.options.tangential_reduce) text += " tangential_reduce on";
  return text;
}

// Contacts of one particle that are evaluated (beyond any plausible packing).
constexpr std::size_t kMaxContacts = 64;
// Wall contacts whose laws are run together.
constexpr std::size_t kWallChunk = 64;
static_assert(kMaxContacts <= kWallChunk, "one particle's mesh contacts fit in one chunk");
// Below this many particles a parallel region costs more than it saves.
constexpr std::size_t kParallelMin = 4096;

// Adds the forces and torques of a chunk of wall contacts to their particles, in chunk order,
// and keeps the deepest overlap relative to the radius and its particle's tag.
void add_wall_results(Particles& P, const WallContact* chunk, const ContactResult* results,
                      std::size_t count, double& worst, long& worst_tag) {
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = chunk[k].i;
    P.f[i] += results[k].force;
    P.torque[i] += results[k].torque_i;
    const double overlap = chunk[k].overlap;
    if (overlap > worst * P.radius[i]) {
      worst = overlap / P.radius[i];
      worst_tag = static_cast<long>(P.tag[i]);
    }
  }
}

}  // namespace

FixWallGran::FixWallGran(Simulation& sim, const Command& command) : Fix(sim, command) {
  const auto& a = args();
  std::size_t p = parse_model_types(a, 0, spec_);
  if (p >= a.size()) throw EngineError("expected 'primitive' or 'mesh' after the model");
  if (a[p] == "primitive") {
    ++p;
    if (p + 1 >= a.size() || a[p] != "type")
      throw EngineError("expected 'type T' after 'primitive'");
    const long t = parse_int(a[p + 1], "wall type");
    if (t < 1 || t > sim.ntypes)
      throw EngineError("wall type " + a[p + 1] + " must be between 1 and the " +
                        std::to_string(sim.ntypes) + " atom types of create_box");
    wall_type_ = static_cast<int>(t);
    p += 2;
    wall_ = PrimitiveWall::parse(a, p);
    history_ = sim.atoms.register_extra("wall/gran:" + id() + ":primitive", kHistorySize);
  } else if (a[p] == "mesh") {
    mesh_mode_ = true;
    ++p;
    if (p + 1 >= a.size() || a[p] != "n_meshes")
      throw EngineError("expected 'n_meshes N' after 'mesh'");
    const long n = parse_int(a[p + 1], "n_meshes");
    if (n < 1) throw EngineError("n_meshes must be >= 1");
    p += 2;
    if (p >= a.size() || a[p] != "meshes") throw EngineError("expected 'meshes ID1 ...'");
    ++p;
    if (p + static_cast<std::size_t>(n) > a.size())
      throw EngineError("'meshes' lists fewer than n_meshes = " + std::to_string(n) + " IDs");
    for (long k = 0; k < n; ++k, ++p) {
      const std::string& mid = a[p];
      if (std::find(mesh_ids_.begin(), mesh_ids_.end(), mid) != mesh_ids_.end())
        throw EngineError("mesh '" + mid + "' is listed twice");
      Fix* f = sim.find_fix(mid);
      if (!f) throw EngineError("unknown mesh fix '" + mid + "' (define it before the wall)");
      if (!dynamic_cast<FixMeshSurface*>(f))
        throw EngineError("fix '" + mid + "' is not a fix mesh/surface");
      mesh_ids_.push_back(mid);
    }
    history_ =
        sim.atoms.register_extra("wall/gran:" + id() + ":mesh", kMeshSlots * kMeshSlotWidth);
    live_ = sim.atoms.register_extra("wall/gran:" + id() + ":mesh_live", 1);
  } else {
    throw EngineError("expected 'primitive' or 'mesh', got '" + a[p] + "'");
  }
  // Model keywords (limitForce, ...) follow the wall definition, as in LIGGGHTS.
  while (p < a.size())
    if (!parse_model_keyword(a, p, spec_))
      throw EngineError("unexpected '" + a[p] +
                        "' after the wall definition (wall keywords such as shear or "
                        "store_force are not supported by this engine)");
  check_model();
}

void FixWallGran::check_model() const {
  const ContactModel& pair = sim_.pair_model();
  if (!same_spec(pair.spec(), spec_))
    throw EngineError("the wall model '" + describe(spec_) +
                      "' differs from the pair style's '" + describe(pair.spec()) + "'");
}

void FixWallGran::check_single_mesh_wall() const {
  // LIGGGHTS 3.8 runs with at most one mesh wall/gran fix (it lists every mesh); the check is
  // made at run, as there, so that a deck may replace the fix (unfix, then fix again) before.
  for (const auto& f : sim_.fixes) {
    const auto* other = dynamic_cast<const FixWallGran*>(f.get());
    if (other == nullptr || other == this || !other->mesh_mode()) continue;
    const SourceLocation& w = other->where();
    throw DeckError(w, "fix",
                    "fix " + other->id() + " is a second fix wall/gran with meshes at run (fix " +
                        id() + " at " + where().file + ":" + std::to_string(where().line) +
                        " is the first); LIGGGHTS 3.8 runs with one: list every mesh in a single "
                        "fix (mesh n_meshes N meshes ID1 ... IDN), or unfix the other first");
  }
}

void FixWallGran::init() {
  check_model();
  if (!mesh_mode_) {
    if (wall_.kind == PrimitiveWall::Kind::kPlane && sim_.domain.periodic(wall_.dim))
      throw EngineError(std::string("a ") + static_cast<char>('x' + wall_.dim) +
                        "plane wall needs a non-periodic boundary in that dimension");
    return;
  }
  check_single_mesh_wall();
  mesh_fixes_.clear();
  meshes_.clear();
  for (const std::string& mid : mesh_ids_) {
    Fix* f = sim_.find_fix(mid);
    auto* mf = f ? dynamic_cast<FixMeshSurface*>(f) : nullptr;
    if (!mf) throw EngineError("mesh fix '" + mid + "' used by fix " + id() + " no longer exists");
    mf->mark_used_by_wall();
    mesh_fixes_.push_back(mf);
    meshes_.push_back(&mf->mesh());
  }
  list_.force_rebuild();
  stress_bits_.assign(meshes_.size(), 0);
  reference_.assign(meshes_.size(), Vec3{});
  const int nthreads = std::max(1, omp_get_max_threads());
  scratch_.resize(nthreads);
  for (Scratch& s : scratch_) {
    s.contacts.reserve(16);
    s.history.reserve(16);
    s.overflow.assign(kMaxContacts * kHistorySize, 0.0);
    s.force.assign(meshes_.size(), Vec3{});
    s.torque.assign(meshes_.size(), Vec3{});
  }
}

HookWork FixWallGran::post_force_work() {
  HookWork work;
  if (mesh_mode_) {  // per-thread sums of the loads on the meshes; one region of its own
    work.before = [this] { mesh_forces(); };
    return work;
  }
  work.before = [this] {
    const Particles& P = sim_.atoms;
    if (near_builds_ != sim_.neighbor.builds() || near_count_of_ != P.size()) find_near_primitive();
    worst_ = 0.0;
    worst_tag_ = -1;
  };
  work.share = [this](std::size_t begin, std::size_t end) { primitive_share(begin, end); };
  work.after = [this] { finish_step(worst_, worst_tag_, 0); };
  return work;
}

void FixWallGran::find_near_primitive() {
  Particles& P = sim_.atoms;
  const std::size_t n = P.size();
  const std::uint32_t bit = group_bit();
  double* hist_all = P.extra(history_).data();
  const NeighborList& list = sim_.neighbor;
  // Without the skin bound every particle stays a candidate, checked at every step.
  const double margin = list.bounds_motion() ? list.skin : 1e300;
  near_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 normal;
    double dist = 0.0;
    if ((P.mask[i] & bit) && wall_.contact(P.x[i], P.radius[i] + margin, normal, dist))
      near_.push_back(i);
    else
      std::fill_n(hist_all + i * kHistorySize, kHistorySize, 0.0);
  }
  near_builds_ = list.bounds_motion() ? list.builds() : -1;
  near_count_of_ = n;
}

void FixWallGran::primitive_share(std::size_t begin, std::size_t end) {
  Particles& P = sim_.atoms;
  double* hist_all = P.extra(history_).data();
  const ContactModel& model = sim_.pair_model();
  const ContactStep step = sim_.wall_step();
  double my_worst = 0.0;
  long my_tag = -1;
  // The candidates (sorted) in this share of the particles.
  const auto from = std::lower_bound(near_.begin(), near_.end(), begin);
  const auto to = std::lower_bound(from, near_.end(), end);
  // Contacts are collected in chunks and their laws run together (ContactModel::wall_forces,
  // two at a time); each particle has one contact with this wall, so the order in which the
  // forces are added changes no sum.
  WallContact chunk[kWallChunk];
  ContactResult results[kWallChunk];
  std::size_t count = 0;
  auto flush = [&]() {
    model.wall_forces(P, sim_.material, step, chunk, count, results);
    add_wall_results(P, chunk, results, count, my_worst, my_tag);
    count = 0;
  };
  for (auto it = from; it != to; ++it) {
    const std::size_t i = *it;
    double* hist = hist_all + i * kHistorySize;
    Vec3 normal;
    double dist = 0.0;
    if (!wall_.contact(P.x[i], P.radius[i], normal, dist)) {
      std::fill(hist, hist + kHistorySize, 0.0);
      continue;
    }
    WallContact& c = chunk[count++];
    c.i = i;
    c.normal = normal;
    c.overlap = P.radius[i] - dist;
    c.dist = dist;
    c.wall_velocity = Vec3{};
    c.wall_type = wall_type_;
    c.history = hist;
    if (count == kWallChunk) flush();
  }
  flush();
#pragma omp critical
  if (my_worst > worst_ || (my_worst == worst_ && my_tag >= 0 && my_tag < worst_tag_)) {
    worst_ = my_worst;
    worst_tag_ = my_tag;
  }
}

void FixWallGran::mesh_forces() {
  Particles& P = sim_.atoms;
  const std::size_t n = P.size();
  const std::uint32_t bit = group_bit();
  // Either way the list now knows how far the particles and meshes moved since its build.
  if (list_.due(P, meshes_)) list_.build(P, bit, meshes_, sim_.neighbor.skin);
  const double* build_dist = list_.dist.data();
  const double* mesh_shift = list_.mesh_shift().data();
  const bool same_list = slots_checked_for_build_ == list_.builds();
  slots_checked_for_build_ = list_.builds();
  const std::size_t nm = meshes_.size();
  std::vector<std::uint32_t>& stress_bits = stress_bits_;
  std::vector<Vec3>& ref = reference_;
  for (std::size_t m = 0; m < nm; ++m) {
    stress_bits[m] = mesh_fixes_[m]->tracks_stress() ? mesh_fixes_[m]->group_bit() : 0;
    ref[m] = mesh_fixes_[m]->reference_point();
  }
  double* slots_all = P.extra(history_).data();
  double* live_all = P.extra(live_).data();
  const int* first = list_.first.data();
  const TriRef* refs = list_.refs.data();
  double worst = 0.0;
  long worst_tag = -1, overflow = 0;
  const int nthreads = static_cast<int>(scratch_.size());
  // Cleared here, not in the parallel region: with few particles only thread 0 runs it.
  for (Scratch& s : scratch_) {
    std::fill(s.force.begin(), s.force.end(), Vec3{});
    std::fill(s.torque.begin(), s.torque.end(), Vec3{});
  }
  const ContactModel& model = sim_.pair_model();
  const ContactStep step = sim_.wall_step();
#pragma omp parallel num_threads(nthreads) if (n >= kParallelMin) reduction(+ : overflow)
  {
    Scratch& s = scratch_[omp_get_thread_num()];
    double my_worst = 0.0;
    long my_tag = -1;
    const ParticleShare own =
        sim_.neighbor.partition().share(n, omp_get_thread_num(), omp_get_num_threads());
    // Contacts are collected over particles in chunks and their laws run together
    // (ContactModel::wall_forces, as for primitive walls); their forces are then added in the
    // order the contacts were found, so every sum is that of one contact at a time.
    WallContact chunk[kWallChunk];
    ContactResult results[kWallChunk];
    std::uint32_t chunk_mesh[kWallChunk];
    Vec3 chunk_point[kWallChunk];
    std::size_t count = 0;
    auto flush = [&]() {
      model.wall_forces(P, sim_.material, step, chunk, count, results);
      add_wall_results(P, chunk, results, count, my_worst, my_tag);
      for (std::size_t k = 0; k < count; ++k) {
        const std::uint32_t m = chunk_mesh[k];
        if (P.mask[chunk[k].i] & stress_bits[m]) {
          s.force[m] -= results[k].force;
          s.torque[m] -= cross(chunk_point[k] - ref[m], results[k].force);
        }
      }
      count = 0;
    };
    for (std::size_t i = own.begin; i < own.end; ++i) {
      const int candidates = first[i + 1] - first[i];
      if (candidates == 0 && same_list) continue;
      double* slots = slots_all + i * kMeshSlots * kMeshSlotWidth;
      s.contacts.clear();
      if (P.mask[i] & bit)
        find_mesh_contacts(P.x[i], P.radius[i], refs + first[i], candidates, meshes_, s.contacts,
                           {build_dist + first[i], std::sqrt(list_.moved2(i)), mesh_shift});
      // Most particles near a mesh touch none of it and hold no slot: their slots stay unread.
      std::uint32_t live = static_cast<std::uint32_t>(live_all[i]);
      if (s.contacts.empty()) {
        if (live != 0) {  // contacts that opened
          release_slots(slots, live);
          live_all[i] = 0.0;
        }
        continue;
      }
      if (s.contacts.size() > kMaxContacts) s.contacts.resize(kMaxContacts);
      const int unkept =
          assign_history_slots(slots, live, s.contacts, meshes_, s.history, s.overflow.data());
      live_all[i] = static_cast<double>(live);
      overflow += unkept;
      if (count + s.contacts.size() > kWallChunk) flush();
      for (std::size_t k = 0; k < s.contacts.size(); ++k) {
        const MeshContact& c = s.contacts[k];
        const TriMesh& mesh = *meshes_[c.mesh];
        WallContact& w = chunk[count];
        w.i = i;
        w.normal = c.normal;
        w.overlap = P.radius[i] - c.dist;
        w.dist = c.dist;
        w.wall_velocity = mesh.moving() ? mesh.velocity_at(c.tri, c.cp) : Vec3{};
        w.wall_type = mesh_fixes_[c.mesh]->wall_type();
        w.history = s.history[k];
        chunk_mesh[count] = c.mesh;
        chunk_point[count] = c.cp.point;
        ++count;
      }
      // Contacts past the slots keep their history in the thread's overflow buffer, which
      // the next particle reuses.
      if (unkept > 0) flush();
    }
    flush();
#pragma omp critical
    if (my_worst > worst || (my_worst == worst && my_tag >= 0 && my_tag < worst_tag)) {
      worst = my_worst;
      worst_tag = my_tag;
    }
  }
  // Fixed-order reduction of the loads on the meshes.
  for (std::size_t m = 0; m < nm; ++m) {
    if (!stress_bits[m]) continue;
    Vec3 f, t;
    for (const Scratch& s : scratch_) {
      f += s.force[m];
      t += s.torque[m];
    }
    mesh_fixes_[m]->add_wall_load(f, t);
  }
  finish_step(worst, worst_tag, overflow);
}

void FixWallGran::finish_step(double worst_ratio, long worst_tag, long overflow) {
  if (worst_ratio > DeepOverlaps::kRatio)
    sim_.note_deep_overlap(worst_ratio, worst_tag, "wall " + id());
  if (overflow > 0 && !overflow_warned_) {
    overflow_warned_ = true;
    sim_.warning("fix " + id() + ": a particle touches more than " + std::to_string(kMeshSlots) +
                 " mesh triangles at step " + std::to_string(sim_.step) +
                 "; the extra contacts get no tangential history");
  }
}

}  // namespace dem

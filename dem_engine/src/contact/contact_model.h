#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "contact/contact_types.h"
#include "contact/material.h"
#include "core/domain.h"
#include "core/neighbor.h"
#include "core/particles.h"

namespace dem {

// Which sub-models make up the contact law (LIGGGHTS `model hertz tangential history
// [cohesion sjkr|off] [rolling_friction epsd2|off] [surface default]` in this order, then
// `limitForce`, `tangential_damping` and, with cohesion sjkr, `tangential_reduce`, each on|off).
struct ModelSpec {
  bool cohesion_sjkr = false;
  bool rolling_epsd2 = false;
  ContactOptions options;
};

// Parses the model types starting at words[pos] (model ... [surface default]); returns the
// index of the first word after them.
std::size_t parse_model_types(const std::vector<std::string>& words, std::size_t pos,
                              ModelSpec& spec);
// Parses one `keyword on|off` of the chosen models at words[pos] and advances pos past it;
// returns false (pos unchanged) when words[pos] is not such a keyword.
bool parse_model_keyword(const std::vector<std::string>& words, std::size_t& pos,
                         ModelSpec& spec);
// pair_style gran: the model types, then only model keywords.
void parse_pair_model(const std::vector<std::string>& words, std::size_t pos, ModelSpec& spec);

// Buffers of the parallel pair loop, kept between steps. A thread adds the forces of its pairs
// on its own particles straight into the particle arrays; those on partners in later shares
// (the list holds a pair under its lower index) it sums here, and the owners add them in. It
// reads the positions, velocities and spins of those partners from copies that their owners
// write at the start of the loop (ghosts, as between the ranks of LIGGGHTS). So no thread
// touches the positions, velocities, spins, forces or torques of another share, which that
// share's thread zeroes and integrates every step: only these buffers change cores, as
// contiguous blocks, instead of lines scattered over another share that its kicks then have to
// take back from the other core.
struct PairScratch {
  // [thread][particle] for every thread but the last: its sums on partners past its share.
  std::vector<std::vector<Vec3>> force, torque;
  // Per thread: the window of partners past its share, [share end, window_end), and the first
  // particle of its share with a partner in it; found once per neighbour build.
  std::vector<std::size_t> window_end, cross_from;
  // [thread][particle - share end]: the ghosts of that window.
  std::vector<std::vector<Vec3>> ghost_x, ghost_v, ghost_omega;
  // Per thread: the last loop (epoch) whose ghosts it has written; a cache line each.
  struct alignas(64) Flag {
    std::atomic<long> epoch{0};
  };
  std::unique_ptr<Flag[]> written;
  long epoch = 0;
  const NeighborList* list_of = nullptr;  // the list and build the windows were found for
  long list_build = -1;
  int team = 0;
  std::size_t n = 0;
  // Sizes the buffers and finds the windows for n particles and a team of nthreads.
  void size_for(const NeighborList& list, std::size_t n, int nthreads);
};

struct PairForceArgs {
  Particles& atoms;
  NeighborList& list;
  const MaterialTable& material;
  const Domain& domain;
  double dt;
  bool update_history;  // false while a run is set up (see ContactStep)
  // Group bit of the first fix freeze (0 if none): a pair with a frozen particle has the
  // effective mass of the other particle, as in LIGGGHTS.
  std::uint32_t freeze_bit;
  PairScratch& scratch;
  double max_overlap_ratio = 0.0;  // out: largest overlap / smaller radius
  long max_overlap_tag = -1;       // out: tag of a particle in that contact
  long contacts = 0;               // out: touching pairs
};

// One contact of particle i with a wall or mesh surface (walls reuse the pair model). Its law
// sees the wall as a partner of radius 0 and infinite mass: R* = r_i, m* = m_i, lever arm
// r_i - overlap / 2 (as for particle pairs, LIGGGHTS), relative velocity v_i - wall_velocity,
// the wall not rotating.
struct WallContact {
  std::size_t i = 0;
  Vec3 normal;  // unit normal from the wall towards the particle centre
  double overlap = 0.0, dist = 0.0;
  Vec3 wall_velocity;
  int wall_type = 1;           // atom type of the wall material
  double* history = nullptr;   // kHistorySize doubles
};

// The contact law chosen at run time; the per-contact code is composed at compile time from
// one sub-model per file (normal_hertz.h, tangential_history.h, cohesion_*.h, rolling_*.h).
class ContactModel {
 public:
  explicit ContactModel(ModelSpec spec) : spec_(spec) {}
  virtual ~ContactModel() = default;
  const ModelSpec& spec() const { return spec_; }
  // One contact: updates history (kHistorySize doubles) and fills result.
  virtual void evaluate(const ContactInput& c, const PairParams& p, const ContactStep& step,
                        double* history, ContactResult& result) const = 0;
  // Many wall contacts at once (see WallContact): results[k] is the law of contacts[k], bit
  // for bit as evaluate() gives it one contact at a time.
  virtual void wall_forces(const Particles& atoms, const MaterialTable& material,
                           const ContactStep& step, const WallContact* contacts, std::size_t count,
                           ContactResult* results) const = 0;
  // All particle pairs of the neighbour list; sets f and torque of every particle to the sum
  // of its pair forces and torques.
  virtual void pair_forces(PairForceArgs& args) const = 0;

 private:
  ModelSpec spec_;
};

std::unique_ptr<ContactModel> make_contact_model(const ModelSpec& spec);

// Contacts per pack of the pair law on this CPU: 8 with AVX-512, else 4 (same results).
int contact_pack_lanes();

}  // namespace dem

#pragma once
#include <memory>

#include "core/compute.h"

namespace dem {

// Factories of the compute styles; make_compute() dispatches on the style name.
std::unique_ptr<Compute> make_erotate_sphere(Simulation& sim, const Command& command);
std::unique_ptr<Compute> make_contact_atom(Simulation& sim, const Command& command);
std::unique_ptr<Compute> make_reduce(Simulation& sim, const Command& command);
std::unique_ptr<Compute> make_pair_gran_local(Simulation& sim, const Command& command);

}  // namespace dem

#pragma once
#include "contact/contact_types.h"

namespace dem {

// No cohesion.
struct CohesionNone {
  static void apply(const ContactInput&, const PairParams&, const ContactStep&, double*,
                    ContactResult&) {}
};

}  // namespace dem

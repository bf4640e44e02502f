#pragma once
#include "contact/contact_types.h"

namespace dem {

// No rolling resistance.
struct RollingNone {
  static void apply(const ContactInput&, const PairParams&, const ContactStep&, double*,
                    ContactResult&) {}
};

}  // namespace dem

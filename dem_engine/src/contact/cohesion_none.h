#pragma once
#include "contact/contact_types.h"

namespace dem {

// No cohesion.
struct CohesionNone {
  template <class R>
  static void apply(const ContactInputT<R>&, const PairParamsT<R>&, const ContactStep&, R*,
                    ContactResultT<R>&) {}
};

}  // namespace dem

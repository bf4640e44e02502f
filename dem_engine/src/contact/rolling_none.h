#pragma once
#include "contact/contact_types.h"

namespace dem {

// No rolling resistance.
struct RollingNone {
  template <class R>
  static void apply(const ContactInputT<R>&, const PairParamsT<R>&, const ContactStep&, R*,
                    ContactResultT<R>&) {}
};

}  // namespace dem

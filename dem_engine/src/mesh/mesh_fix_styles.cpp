#include "fix/fix.h"

namespace dem {
void register_mesh_fix_styles(FixRegistry&) {}
}  // namespace dem

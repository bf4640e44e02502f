#pragma once
#include <cstddef>
#include <vector>

#include "core/compute.h"

namespace dem {

// Local values of a compute (LAMMPS "local array"): one row per entity of the current step
// (for pair/gran/local, per particle contact) and a fixed number of columns, row-major.
struct LocalArray {
  std::size_t columns = 0;
  std::vector<double> values;
  std::size_t rows() const { return columns == 0 ? 0 : values.size() / columns; }
  double at(std::size_t row, std::size_t column) const { return values[row * columns + column]; }
};

// A compute that produces a local array, read by `dump local` as c_ID[i] (1-based column).
class LocalCompute : public Compute {
 public:
  using Compute::Compute;
  // Number of columns of local_array() (may depend on the pair style, so asked at each use).
  virtual std::size_t local_columns() const = 0;
  // The rows at the current state of the simulation.
  virtual LocalArray local_array() const = 0;
};

}  // namespace dem

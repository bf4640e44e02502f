#pragma once
#include <cstddef>
#include <vector>

namespace dem {

// The averaging of fix ave/time (LAMMPS semantics): `nrepeat` samples form one block average;
// block averages are then combined as `one` (latest block), `running` (all blocks so far) or
// `window` (the last M blocks). Values flagged `off` are not averaged: the latest sample is kept.
class TimeAverage {
 public:
  enum class Mode { One, Running, Window };
  TimeAverage(std::size_t nvalues, long nrepeat, Mode mode, long window, std::vector<bool> off);
  // Adds one sample (nvalues numbers); returns true when it completed a block, i.e. when the
  // output values changed.
  bool add(const std::vector<double>& sample);
  // Current output value k (0 before the first completed block).
  double value(std::size_t k) const;
  std::size_t size() const { return nvalues_; }
  long samples_in_block() const { return irepeat_; }

 private:
  std::size_t nvalues_;
  long nrepeat_;
  Mode mode_;
  long window_;
  std::vector<bool> off_;
  long irepeat_ = 0;
  std::vector<double> block_, total_;
  std::vector<std::vector<double>> history_;  // window mode: the last `window_` blocks
  long iwindow_ = 0;
  bool window_full_ = false;
  double norm_ = 0.0;
};

}  // namespace dem

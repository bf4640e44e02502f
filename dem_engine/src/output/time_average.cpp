#include "output/time_average.h"

#include "deck/errors.h"

namespace dem {

TimeAverage::TimeAverage(std::size_t nvalues, long nrepeat, Mode mode, long window,
                         std::vector<bool> off)
    : nvalues_(nvalues),
      nrepeat_(nrepeat),
      mode_(mode),
      window_(window),
      off_(std::move(off)),
      block_(nvalues, 0.0),
      total_(nvalues, 0.0) {
  if (nrepeat_ < 1) throw EngineError("Nrepeat must be >= 1");
  if (mode_ == Mode::Window && window_ < 1) throw EngineError("ave window M needs M >= 1");
  off_.resize(nvalues_, false);
  if (mode_ == Mode::Window)
    history_.assign(static_cast<std::size_t>(window_), std::vector<double>(nvalues_, 0.0));
}

bool TimeAverage::add(const std::vector<double>& sample) {
  if (sample.size() != nvalues_) throw EngineError("time average: wrong number of values");
  if (irepeat_ == 0) block_.assign(nvalues_, 0.0);
  for (std::size_t k = 0; k < nvalues_; ++k) {
    if (off_[k]) block_[k] = sample[k];
    else block_[k] += sample[k];
  }
  if (++irepeat_ < nrepeat_) return false;
  irepeat_ = 0;
  for (std::size_t k = 0; k < nvalues_; ++k)
    if (!off_[k]) block_[k] /= static_cast<double>(nrepeat_);

  if (mode_ == Mode::One) {
    total_ = block_;
    norm_ = 1.0;
  } else if (mode_ == Mode::Running) {
    for (std::size_t k = 0; k < nvalues_; ++k) total_[k] += block_[k];
    norm_ += 1.0;
  } else {
    auto& slot = history_[static_cast<std::size_t>(iwindow_)];
    for (std::size_t k = 0; k < nvalues_; ++k) {
      total_[k] += block_[k];
      if (window_full_) total_[k] -= slot[k];
      slot[k] = block_[k];
    }
    if (++iwindow_ == window_) {
      iwindow_ = 0;
      window_full_ = true;
    }
    norm_ = static_cast<double>(window_full_ ? window_ : iwindow_);
  }
  // Values that are not averaged always report the latest sample.
  for (std::size_t k = 0; k < nvalues_; ++k)
    if (off_[k]) total_[k] = norm_ * block_[k];
  return true;
}

double TimeAverage::value(std::size_t k) const {
  if (k >= nvalues_) throw EngineError("time average: no value " + std::to_string(k + 1));
  return norm_ > 0.0 ? total_[k] / norm_ : 0.0;
}

}  // namespace dem

#pragma once
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "fix/fix.h"
#include "output/time_average.h"

namespace dem {

// `fix ID group print N "text" [file F | append F] [screen yes|no] [title "..."|none]`: prints the
// text with its variables substituted every N steps to the screen/log and to a file.
class FixPrint : public Fix {
 public:
  FixPrint(Simulation& sim, const Command& command);
  void end_of_step() override;

 private:
  long every_ = 1;
  std::string text_;
  bool screen_ = true;
  std::ofstream file_;
};

// `fix ID group ave/time NEVERY NREPEAT NFREQ value1 ... [mode scalar] [ave one|running|window M]
//  [start S] [off I] [file F] [overwrite] [title1 T] [title2 T]`; values are c_ID, c_ID[i], f_ID,
// f_ID[i] and v_name (equal-style). f_ID (one value) or f_ID[i] return the current averages.
class FixAveTime : public Fix {
 public:
  FixAveTime(Simulation& sim, const Command& command);
  void init() override;
  void setup() override { end_of_step(); }
  void end_of_step() override;
  double scalar() const override;
  double vector(int index) const override;

 private:
  struct Value {
    char kind = 'v';  // 'c' compute, 'f' fix, 'v' variable
    std::string id;
    int index = 0;    // 0: scalar, i >= 1: element i of a global vector
    std::string text;  // as written in the deck
  };
  double evaluate(const Value& value) const;
  long next_valid() const;
  void write_output();

  long nevery_ = 1, nrepeat_ = 1, nfreq_ = 1, start_ = 0;
  long next_ = 0;
  std::vector<Value> inputs_;
  std::unique_ptr<TimeAverage> average_;
  std::vector<double> sample_;
  std::string path_, header_;
  bool overwrite_ = false;
  std::ofstream file_;
};

}  // namespace dem

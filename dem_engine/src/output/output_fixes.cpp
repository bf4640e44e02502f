#include "output/output_fixes.h"

#include <cstdio>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "output/output_file.h"

namespace dem {

// --- fix print -----------------------------------------------------------------------------

FixPrint::FixPrint(Simulation& sim, const Command& command) : Fix(sim, command) {
  const auto& a = args();
  require_args(a, 2, "fix ID group print N \"text\" [file F|append F] [screen yes|no] [title T]");
  every_ = parse_int(a[0], "fix print N");
  if (every_ < 1) throw EngineError("fix print N must be >= 1");
  text_ = a[1];
  std::string title = "# Fix print output for fix " + id();
  std::string path;
  bool append = false;
  for (std::size_t i = 2; i < a.size(); i += 2) {
    if (i + 1 >= a.size()) throw EngineError("fix print keyword '" + a[i] + "' needs a value");
    const std::string& key = a[i];
    if (key == "file" || key == "append") {
      path = a[i + 1];
      append = key == "append";
    } else if (key == "screen") {
      screen_ = parse_yes_no(a[i + 1], "screen");
    } else if (key == "title") {
      title = a[i + 1];
    } else {
      throw EngineError("unknown fix print keyword '" + key + "'");
    }
  }
  if (!path.empty()) {
    file_.open(path, append ? std::ios::app : std::ios::trunc);
    if (!file_) throw EngineError("cannot open fix print file '" + path + "'");
    if (title != "none") file_ << title << '\n' << std::flush;
  }
}

void FixPrint::end_of_step() {
  if (sim_.step % every_ != 0) return;
  const std::string line = sim_.input().substitute(text_);
  if (screen_) sim_.message(line);
  if (file_.is_open()) file_ << line << '\n' << std::flush;
}

// --- fix ave/time --------------------------------------------------------------------------

FixAveTime::FixAveTime(Simulation& sim, const Command& command) : Fix(sim, command) {
  const auto& a = args();
  require_args(a, 4, "fix ID group ave/time Nevery Nrepeat Nfreq value1 ... keyword args");
  nevery_ = parse_int(a[0], "Nevery");
  nrepeat_ = parse_int(a[1], "Nrepeat");
  nfreq_ = parse_int(a[2], "Nfreq");
  if (nevery_ < 1 || nrepeat_ < 1 || nfreq_ < 1)
    throw EngineError("Nevery, Nrepeat and Nfreq must be >= 1");
  if (nfreq_ % nevery_ != 0 || (nrepeat_ - 1) * nevery_ >= nfreq_)
    throw EngineError("Nfreq must be a multiple of Nevery and larger than (Nrepeat-1)*Nevery");

  std::size_t i = 3;
  for (; i < a.size(); ++i) {
    const std::string& word = a[i];
    if (word.size() < 3 || word[1] != '_' || (word[0] != 'c' && word[0] != 'f' && word[0] != 'v'))
      break;
    Value in;
    in.kind = word[0];
    in.text = word;
    std::string name = word.substr(2);
    const std::size_t bracket = name.find('[');
    if (bracket != std::string::npos) {
      if (name.back() != ']' || in.kind == 'v')
        throw EngineError("bad fix ave/time value '" + word + "'");
      in.index = static_cast<int>(
          parse_int(name.substr(bracket + 1, name.size() - bracket - 2), "index in " + word));
      if (in.index < 1) throw EngineError("index in '" + word + "' must be >= 1");
      name = name.substr(0, bracket);
    }
    if (name.empty()) throw EngineError("bad fix ave/time value '" + word + "'");
    in.id = name;
    if (in.kind == 'c') sim.compute(name);
    else if (in.kind == 'f') sim.fix(name);
    else if (!sim.variables.exists(name) ||
             sim.variables.style(name) != Variables::Style::Equal)
      throw EngineError("fix ave/time variable '" + name + "' is not an equal-style variable");
    inputs_.push_back(in);
  }
  if (inputs_.empty()) throw EngineError("fix ave/time needs at least one value");

  auto mode = TimeAverage::Mode::One;
  long window = 0;
  std::vector<bool> off(inputs_.size(), false);
  std::string title1 = "# Time-averaged data for fix " + id();
  std::string title2 = "# TimeStep";
  for (const auto& in : inputs_) title2 += " " + in.text;
  const auto need = [&](std::size_t k) {
    if (k + 1 >= a.size()) throw EngineError("fix ave/time keyword '" + a[k] + "' needs a value");
  };
  while (i < a.size()) {
    const std::string& key = a[i];
    if (key == "mode") {
      need(i);
      if (a[i + 1] != "scalar")
        throw EngineError("fix ave/time mode '" + a[i + 1] + "' is not supported (only scalar)");
      i += 2;
    } else if (key == "ave") {
      need(i);
      if (a[i + 1] == "one") {
        mode = TimeAverage::Mode::One;
        i += 2;
      } else if (a[i + 1] == "running") {
        mode = TimeAverage::Mode::Running;
        i += 2;
      } else if (a[i + 1] == "window") {
        if (i + 2 >= a.size()) throw EngineError("'ave window' needs M");
        mode = TimeAverage::Mode::Window;
        window = parse_int(a[i + 2], "ave window M");
        i += 3;
      } else {
        throw EngineError("ave must be one, running or window M, got '" + a[i + 1] + "'");
      }
    } else if (key == "start") {
      need(i);
      start_ = parse_int(a[i + 1], "start");
      i += 2;
    } else if (key == "off") {
      need(i);
      const long k = parse_int(a[i + 1], "off");
      if (k < 1 || k > static_cast<long>(inputs_.size()))
        throw EngineError("fix ave/time off " + a[i + 1] + " is not a value number");
      off[static_cast<std::size_t>(k - 1)] = true;
      i += 2;
    } else if (key == "file") {
      need(i);
      path_ = a[i + 1];
      i += 2;
    } else if (key == "overwrite") {
      overwrite_ = true;
      i += 1;
    } else if (key == "title1" || key == "title2" || key == "title3") {
      need(i);
      if (key == "title1") title1 = a[i + 1];
      else if (key == "title2") title2 = a[i + 1];
      i += 2;  // title3 only applies to vector mode
    } else {
      throw EngineError("unknown fix ave/time keyword '" + key + "'");
    }
  }
  average_ = std::make_unique<TimeAverage>(inputs_.size(), nrepeat_, mode, window, off);
  sample_.resize(inputs_.size());
  header_ = title1 + "\n" + title2 + "\n";
  if (overwrite_ && !path_.empty()) {
    write_file_atomically(path_, header_);
  } else if (!path_.empty()) {
    file_.open(path_, std::ios::trunc);
    if (!file_) throw EngineError("cannot open fix ave/time file '" + path_ + "'");
    file_ << header_ << std::flush;
  }
  next_ = next_valid();
}

// First step at or after the current one that contributes to an output (LAMMPS nextvalid()).
long FixAveTime::next_valid() const {
  const long step = sim_.step;
  long valid = (step / nfreq_) * nfreq_ + nfreq_;
  while (valid < start_) valid += nfreq_;
  if (valid - nfreq_ == step && nrepeat_ == 1) valid = step;
  else valid -= (nrepeat_ - 1) * nevery_;
  if (valid < step) valid += nfreq_;
  return valid;
}

void FixAveTime::init() {
  if (next_ < sim_.step) next_ = next_valid();
}

double FixAveTime::evaluate(const Value& in) const {
  if (in.kind == 'c') {
    const Compute& c = sim_.compute(in.id);
    return in.index == 0 ? c.scalar() : c.vector(in.index);
  }
  if (in.kind == 'f') {
    const Fix& f = sim_.fix(in.id);
    return in.index == 0 ? f.scalar() : f.vector(in.index);
  }
  return sim_.variables.number(in.id, sim_);
}

void FixAveTime::end_of_step() {
  const long step = sim_.step;
  if (step != next_) return;
  for (std::size_t k = 0; k < inputs_.size(); ++k) sample_[k] = evaluate(inputs_[k]);
  if (!average_->add(sample_)) {
    next_ += nevery_;
    return;
  }
  next_ = step + nfreq_ - (nrepeat_ - 1) * nevery_;
  write_output();
}

void FixAveTime::write_output() {
  if (path_.empty()) return;
  std::string row = format_integer(sim_.step);
  for (std::size_t k = 0; k < inputs_.size(); ++k)
    row += " " + format_number("%g", average_->value(k));
  row += '\n';
  if (overwrite_) {
    // Only the latest output is kept; the file is replaced whole so it is never seen half-written.
    write_file_atomically(path_, header_ + row);
  } else {
    file_ << row << std::flush;
  }
}

double FixAveTime::scalar() const {
  if (inputs_.size() != 1)
    throw EngineError("fix " + id() + " (ave/time) has " + std::to_string(inputs_.size()) +
                      " values: use f_" + id() + "[i]");
  return average_->value(0);
}

double FixAveTime::vector(int index) const {
  if (inputs_.size() == 1)
    throw EngineError("fix " + id() + " (ave/time) has one value: use f_" + id());
  if (index < 1 || index > static_cast<int>(inputs_.size()))
    throw EngineError("fix " + id() + " (ave/time) has no value " + std::to_string(index));
  return average_->value(static_cast<std::size_t>(index - 1));
}

}  // namespace dem

#pragma once
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "io/dump.h"
#include "output/dump_fields.h"

namespace dem {

// Per-particle dumps (custom, custom/vtk): field list, which particles and steps are written,
// and the dump_modify keywords first, sort, pad and (dump custom only) format; every is
// handled by Dump.
class AtomDump : public Dump {
 public:
  AtomDump(Simulation& sim, const Command& command);
  // Writes a snapshot when the step is a multiple of N (or it is the first call and
  // `first yes`), at most once per step, as LAMMPS output does.
  void write() final;
  void modify(const std::vector<std::string>& args) override;

 protected:
  struct Snapshot {
    long step = 0;
    std::vector<std::size_t> particles;              // local indices, in output order
    std::vector<std::vector<double>> compute_values;  // per field (empty unless c_ID)
  };
  virtual void write_snapshot(const Snapshot& snapshot) = 0;
  std::string file_name(long step) const { return expand(step); }
  bool multi_file() const { return file_.find('*') != std::string::npos; }

  std::vector<DumpField> fields_;
  // dump_modify format: one printf format per field (empty: the default %g / integer).
  std::vector<std::string> formats_;
  virtual bool accepts_format() const { return false; }

 private:
  void set_format(const std::string& text);
  std::string expand(long step) const;
  static constexpr long kNever = -1;
  long last_written_ = kNever;
  bool sort_ = false;
};

// `dump ID group custom N FILE fields...`: LAMMPS text snapshots (ITEM: TIMESTEP, NUMBER OF
// ATOMS, BOX BOUNDS, ATOMS). One growing file, or one file per snapshot with '*' in FILE.
class DumpCustom : public AtomDump {
 public:
  DumpCustom(Simulation& sim, const Command& command);

 private:
  bool accepts_format() const override { return true; }
  void write_snapshot(const Snapshot& snapshot) override;
  std::ofstream stream_;  // single-file mode
};

// `dump ID group custom/vtk N FILE fields...`: legacy VTK polydata (points, vertex cells and
// point data; vx vy vz, fx fy fz, omegax.. and tqx.. become the vectors v, f, omega and tq).
class DumpCustomVtk : public AtomDump {
 public:
  DumpCustomVtk(Simulation& sim, const Command& command);

 private:
  void write_snapshot(const Snapshot& snapshot) override;
};

}  // namespace dem

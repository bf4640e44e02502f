#pragma once
#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

#include "io/dump.h"

namespace dem {

// One column of `dump local`: `index` (the 1-based row number) or c_ID[i] (column i of the
// local array of compute ID).
struct LocalDumpColumn {
  std::string name;        // as written in the deck; the header names the column so
  std::string compute_id;  // empty for index
  std::size_t column = 0;  // 0-based column of the compute's local array

  bool is_index() const { return compute_id.empty(); }
};

// Parses the column words of `dump local` (index, c_ID[i] with i >= 1). Throws EngineError for
// other words, c_ID without a column, f_ID and v_name.
std::vector<LocalDumpColumn> parse_local_dump_columns(const std::vector<std::string>& words);

// `dump ID group local N FILE columns...`: the text layout of LIGGGHTS 3.8 (LAMMPS dump local):
//
//   ITEM: TIMESTEP / step / ITEM: NUMBER OF ENTRIES / rows / ITEM: BOX BOUNDS xx yy zz /
//   three lines "lo hi" / ITEM: ENTRIES name1 name2 ... / one line per row
//
// where the ENTRIES line and every row end with a blank, values are printed with %g (index with
// %d) or the formats of `dump_modify ID format "F1 F2 ..."`, each followed by a blank. As in
// LIGGGHTS the dump's group is ignored (the computes select the rows). One growing file, or one
// file per snapshot with '*' in FILE. dump_modify: every, first, pad, format.
class DumpLocal : public Dump {
 public:
  DumpLocal(Simulation& sim, const Command& command);
  // Writes a snapshot when the step is a multiple of N (or it is the first call and
  // `first yes`), at most once per step, as the other dumps.
  void write() override;
  void modify(const std::vector<std::string>& args) override;

 private:
  // The text of one snapshot at the current step.
  std::string snapshot_text() const;
  void set_format(const std::string& text);

  std::vector<LocalDumpColumn> columns_;
  std::vector<std::string> formats_;  // per column; empty: %g (index: %d)
  std::ofstream stream_;              // single-file mode
  static constexpr long kNever = -1;
  long last_written_ = kNever;
};

}  // namespace dem

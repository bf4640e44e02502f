#include "output/local_dump.h"

#include <cstdio>
#include <map>

#include "compute/compute_pair_gran_local.h"
#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "deck/line_lexer_internal.h"
#include "output/dump_fields.h"
#include "output/output_file.h"

namespace dem {

std::vector<LocalDumpColumn> parse_local_dump_columns(const std::vector<std::string>& words) {
  std::vector<LocalDumpColumn> columns;
  for (const std::string& word : words) {
    LocalDumpColumn column;
    column.name = word;
    if (word == "index") {
      columns.push_back(column);
      continue;
    }
    if (word.rfind("f_", 0) == 0 || word.rfind("v_", 0) == 0)
      throw EngineError("dump local: '" + word +
                        "': only compute columns c_ID[i] and index are supported");
    if (word.rfind("c_", 0) != 0)
      throw EngineError("dump local: invalid attribute '" + word +
                        "' (supported: index, c_ID[i])");
    const std::size_t open = word.find('[');
    if (open == std::string::npos)
      throw EngineError("dump local: '" + word +
                        "' names no column; local computes give arrays, write c_ID[i]");
    if (word.back() != ']' || open == 2)
      throw EngineError("dump local: malformed compute column '" + word + "' (expected c_ID[i])");
    const long i = parse_int(word.substr(open + 1, word.size() - open - 2), "dump local column");
    if (i < 1) throw EngineError("dump local: column index in '" + word + "' must be >= 1");
    column.compute_id = word.substr(2, open - 2);
    column.column = static_cast<std::size_t>(i - 1);
    columns.push_back(column);
  }
  return columns;
}

namespace {

// The local compute `id`; throws when it is missing or gives no local values.
const LocalCompute& local_compute(const Simulation& sim, const std::string& id) {
  const Compute& c = sim.compute(id);
  const auto* local = dynamic_cast<const LocalCompute*>(&c);
  if (!local)
    throw EngineError("dump local: compute " + id + " (" + c.style() +
                      ") does not calculate local values");
  return *local;
}

void check_column(const Simulation& sim, const LocalDumpColumn& column) {
  if (column.is_index()) return;
  const std::size_t n = local_compute(sim, column.compute_id).local_columns();
  if (column.column >= n)
    throw EngineError("dump local: " + column.name + " is out of range (compute " +
                      column.compute_id + " has " + std::to_string(n) +
                      (n == 1 ? " column)" : " columns)"));
}

std::string index_text(const std::string& format, long long value) {
  return format.empty() ? format_integer(value) : integer_text(format, value);
}

}  // namespace

DumpLocal::DumpLocal(Simulation& sim, const Command& command) : Dump(sim, command) {
  if (every() < 1) throw EngineError("dump N must be >= 1");
  const std::string& f = file_;
  if (f.find('%') != std::string::npos)
    throw EngineError("dump file '" + f + "': per-processor files ('%') are not supported");
  if ((f.size() > 3 && f.compare(f.size() - 3, 3, ".gz") == 0) ||
      (f.size() > 4 && f.compare(f.size() - 4, 4, ".bin") == 0))
    throw EngineError("dump file '" + f + "': gzipped and binary dumps are not supported");
  if (args_.empty()) throw EngineError("dump local needs columns (index, c_ID[i])");
  columns_ = parse_local_dump_columns(args_);
  bool any_compute = false;
  for (const auto& column : columns_) {
    check_column(sim, column);
    any_compute = any_compute || !column.is_index();
  }
  if (!any_compute) throw EngineError("dump local needs at least one compute column c_ID[i]");
}

void DumpLocal::modify(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); i += 2) {
    const std::string& key = args[i];
    if (i + 1 >= args.size()) throw EngineError("dump_modify keyword '" + key + "' needs a value");
    const std::string& value = args[i + 1];
    if (key == "format") {
      set_format(value);
    } else {
      Dump::modify({key, value});
    }
  }
}

// One format per column, separated by blanks; values of computes are floating point, so their
// formats need one floating-point conversion (LIGGGHTS would print garbage for %d).
void DumpLocal::set_format(const std::string& text) {
  formats_.clear();
  if (text == "none") return;
  const std::vector<std::string> tokens = format_tokens(text, columns_.size(), "columns");
  std::vector<std::string> formats;
  for (std::size_t k = 0; k < columns_.size(); ++k) {
    if (columns_[k].is_index()) {
      formats.push_back(integer_format(tokens[k], "the index column"));
    } else {
      deck_lexer::format_number(tokens[k], 0.0);  // validates: one floating-point conversion
      formats.push_back(tokens[k]);
    }
  }
  formats_ = std::move(formats);
}

std::string DumpLocal::snapshot_text() const {
  // Each compute is evaluated once per snapshot, however many of its columns are written.
  for (const auto& column : columns_) check_column(sim_, column);  // the pair style may change
  std::map<std::string, LocalArray> arrays;
  std::size_t rows = 0;
  std::string rows_from;
  for (const auto& column : columns_) {
    if (column.is_index() || arrays.count(column.compute_id)) continue;
    LocalArray array = local_compute(sim_, column.compute_id).local_array();
    if (!rows_from.empty() && array.rows() != rows)
      throw EngineError("dump " + id() + ": computes " + rows_from + " and " + column.compute_id +
                        " give different numbers of rows");
    rows = array.rows();
    rows_from = column.compute_id;
    arrays.emplace(column.compute_id, std::move(array));
  }

  const Domain& box = sim_.domain;
  std::string text;
  text.reserve(32 * (rows + 4) * (columns_.size() + 1));
  text += "ITEM: TIMESTEP\n" + format_integer(sim_.step) + "\n";
  text += "ITEM: NUMBER OF ENTRIES\n" + format_integer(static_cast<long long>(rows)) + "\n";
  text += "ITEM: BOX BOUNDS";
  for (int d = 0; d < 3; ++d) {
    text += ' ';
    text += box.boundary[d];
    text += box.boundary[d];
  }
  text += '\n';
  for (int d = 0; d < 3; ++d)
    text += format_number("%g", box.lo[d]) + " " + format_number("%g", box.hi[d]) + "\n";
  text += "ITEM: ENTRIES ";
  for (const auto& column : columns_) text += column.name + " ";
  text += '\n';
  std::vector<const LocalArray*> sources(columns_.size(), nullptr);
  for (std::size_t k = 0; k < columns_.size(); ++k)
    if (!columns_[k].is_index()) sources[k] = &arrays.at(columns_[k].compute_id);
  static const std::string kDefaultFormat;
  for (std::size_t row = 0; row < rows; ++row) {
    for (std::size_t k = 0; k < columns_.size(); ++k) {
      const LocalDumpColumn& column = columns_[k];
      const std::string& format = formats_.empty() ? kDefaultFormat : formats_[k];
      if (column.is_index()) {
        text += index_text(format, static_cast<long long>(row) + 1);
      } else {
        const double value = sources[k]->at(row, column.column);
        text += format.empty() ? format_number("%g", value)
                               : deck_lexer::format_number(format, value);
      }
      text += ' ';
    }
    text += '\n';
  }
  return text;
}

void DumpLocal::write() {
  const long step = sim_.step;
  if (step == last_written_) return;
  if (step % every() != 0 && !(first_ && last_written_ == kNever)) return;
  const std::string text = snapshot_text();
  if (file_.find('*') != std::string::npos) {
    write_file_atomically(expand_step_pattern(file_, step, pad_), text);
  } else {
    if (!stream_.is_open()) {
      stream_.open(file_, std::ios::trunc);
      if (!stream_) throw EngineError("cannot open dump file '" + file_ + "'");
    }
    // One write per snapshot, flushed, so a reader sees whole snapshots only.
    stream_.write(text.data(), static_cast<std::streamsize>(text.size()));
    stream_.flush();
    if (!stream_) throw EngineError("cannot write dump file '" + file_ + "'");
  }
  last_written_ = step;
}

}  // namespace dem

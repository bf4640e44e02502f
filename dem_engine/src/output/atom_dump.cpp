#include "output/atom_dump.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "core/numbers.h"
#include "core/simulation.h"
#include "deck/errors.h"
#include "deck/line_lexer_internal.h"
#include "output/output_file.h"

namespace dem {

AtomDump::AtomDump(Simulation& sim, const Command& command) : Dump(sim, command) {
  if (every() < 1) throw EngineError("dump N must be >= 1");
  if (file_.find('%') != std::string::npos)
    throw EngineError("dump file '" + file_ + "': per-processor files ('%') are not supported");
  fields_ = parse_dump_fields(args_);
  for (const auto& field : fields_)
    if (field.kind == DumpField::Kind::Compute) sim.compute(field.compute_id);
}

void AtomDump::modify(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); i += 2) {
    const std::string& key = args[i];
    if (i + 1 >= args.size()) throw EngineError("dump_modify keyword '" + key + "' needs a value");
    const std::string& value = args[i + 1];
    if (key == "sort") {
      if (value != "id" && value != "off")
        throw EngineError("dump_modify sort '" + value + "' is not supported (id or off)");
      sort_ = value == "id";
    } else if (key == "format") {
      if (!accepts_format())
        throw EngineError("dump_modify format is only supported for dump custom");
      set_format(value);
    } else {
      Dump::modify({key, value});
    }
  }
}

void AtomDump::set_format(const std::string& text) {
  formats_.clear();
  if (text == "none") return;
  const std::vector<std::string> tokens = format_tokens(text, fields_.size(), "fields");
  for (std::size_t k = 0; k < fields_.size(); ++k) {
    if (fields_[k].integer()) {
      formats_.push_back(integer_format(tokens[k], "an integer field"));
    } else {
      deck_lexer::format_number(tokens[k], 0.0);  // validates: one floating-point conversion
      formats_.push_back(tokens[k]);
    }
  }
}

std::string AtomDump::expand(long step) const { return expand_step_pattern(file_, step, pad_); }

void AtomDump::write() {
  const long step = sim_.step;
  if (step == last_written_) return;
  if (step % every() != 0 && !(first_ && last_written_ == kNever)) return;
  const auto& atoms = sim_.atoms;
  Snapshot snap;
  snap.step = step;
  for (std::size_t i = 0; i < atoms.size(); ++i)
    if (atoms.mask[i] & group_bit_) snap.particles.push_back(i);
  if (sort_)
    std::sort(snap.particles.begin(), snap.particles.end(),
              [&atoms](std::size_t a, std::size_t b) { return atoms.tag[a] < atoms.tag[b]; });
  snap.compute_values.resize(fields_.size());
  for (std::size_t k = 0; k < fields_.size(); ++k) {
    if (fields_[k].kind != DumpField::Kind::Compute) continue;
    const Compute& c = sim_.compute(fields_[k].compute_id);
    if (!c.peratom())
      throw EngineError("dump " + id() + ": compute " + c.id() +
                        " does not compute per-atom values");
    snap.compute_values[k] = c.peratom_values();
    if (snap.compute_values[k].size() != atoms.size())
      throw EngineError("dump " + id() + ": compute " + c.id() + " returned " +
                        std::to_string(snap.compute_values[k].size()) + " values for " +
                        std::to_string(atoms.size()) + " particles");
  }
  write_snapshot(snap);
  last_written_ = step;
}

// --- dump custom ---------------------------------------------------------------------------



DumpCustom::DumpCustom(Simulation& sim, const Command& command) : AtomDump(sim, command) {
  const std::string& f = file_;
  if ((f.size() > 3 && f.compare(f.size() - 3, 3, ".gz") == 0) ||
      (f.size() > 4 && f.compare(f.size() - 4, 4, ".bin") == 0))
    throw EngineError("dump file '" + f + "': gzipped and binary dumps are not supported");
}

void DumpCustom::write_snapshot(const Snapshot& snap) {
  const auto& atoms = sim_.atoms;
  const Domain& box = sim_.domain;
  std::string text;
  text.reserve(64 * (snap.particles.size() + 8));
  text += "ITEM: TIMESTEP\n" + format_integer(snap.step) + "\n";
  text += "ITEM: NUMBER OF ATOMS\n" +
          format_integer(static_cast<long long>(snap.particles.size())) + "\n";
  text += "ITEM: BOX BOUNDS";
  for (int d = 0; d < 3; ++d) {
    text += ' ';
    text += box.boundary[d];
    text += box.boundary[d];
  }
  text += '\n';
  for (int d = 0; d < 3; ++d)
    text += format_number("%g", box.lo[d]) + " " + format_number("%g", box.hi[d]) + "\n";
  text += "ITEM: ATOMS";
  for (const auto& field : fields_) text += " " + field.name;
  text += '\n';
  for (std::size_t i : snap.particles) {
    for (std::size_t k = 0; k < fields_.size(); ++k) {
      const double value = dump_field_value(fields_[k], atoms, i, snap.compute_values[k]);
      if (!formats_.empty()) {  // LIGGGHTS: every user format is followed by a blank
        text += fields_[k].integer() ? integer_text(formats_[k], static_cast<long long>(value))
                                     : deck_lexer::format_number(formats_[k], value);
        text += ' ';
        continue;
      }
      if (k > 0) text += ' ';
      text += fields_[k].integer() ? format_integer(static_cast<long long>(value))
                                   : format_number("%g", value);
    }
    text += '\n';
  }
  if (multi_file()) {
    write_file_atomically(file_name(snap.step), text);
    return;
  }
  if (!stream_.is_open()) {
    stream_.open(file_, std::ios::trunc);
    if (!stream_) throw EngineError("cannot open dump file '" + file_ + "'");
  }
  // One write per snapshot, flushed, so a reader sees whole snapshots only.
  stream_.write(text.data(), static_cast<std::streamsize>(text.size()));
  stream_.flush();
  if (!stream_) throw EngineError("cannot write dump file '" + file_ + "'");
}

// --- dump custom/vtk -----------------------------------------------------------------------

DumpCustomVtk::DumpCustomVtk(Simulation& sim, const Command& command) : AtomDump(sim, command) {
  const std::string& f = file_;
  for (const char* ext : {".vtp", ".vtu", ".pvtp", ".pvtu", ".vtr"}) {
    const std::string e = ext;
    if (f.size() > e.size() && f.compare(f.size() - e.size(), e.size(), e) == 0)
      throw EngineError("dump file '" + f + "': only legacy VTK output (.vtk) is supported");
  }
}

namespace {

using K = DumpField::Kind;

// A point-data array: one scalar field or three fields combined into a vector.
struct VtkArray {
  std::string name;
  std::vector<std::size_t> fields;  // 1 or 3 indices into the field list
  bool integer = false;
};

std::vector<VtkArray> vtk_arrays(const std::vector<DumpField>& fields) {
  struct Triple {
    K a, b, c;
    const char* name;
  };
  static const Triple triples[] = {{K::Vx, K::Vy, K::Vz, "v"},
                                   {K::Fx, K::Fy, K::Fz, "f"},
                                   {K::OmegaX, K::OmegaY, K::OmegaZ, "omega"},
                                   {K::TqX, K::TqY, K::TqZ, "tq"}};
  const auto find = [&fields](K kind) {
    for (std::size_t k = 0; k < fields.size(); ++k)
      if (fields[k].kind == kind) return static_cast<long>(k);
    return -1L;
  };
  std::vector<VtkArray> arrays;
  std::vector<bool> used(fields.size(), false);
  for (std::size_t k = 0; k < fields.size(); ++k)
    if (fields[k].kind == K::X || fields[k].kind == K::Y || fields[k].kind == K::Z)
      used[k] = true;  // positions are the points
  for (const auto& t : triples) {
    const long a = find(t.a), b = find(t.b), c = find(t.c);
    if (a < 0 || b < 0 || c < 0) continue;
    arrays.push_back({t.name,
                      {static_cast<std::size_t>(a), static_cast<std::size_t>(b),
                       static_cast<std::size_t>(c)},
                      false});
    used[a] = used[b] = used[c] = true;
  }
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (used[k]) continue;
    bool duplicate = false;
    for (const auto& array : arrays) duplicate = duplicate || array.name == fields[k].name;
    if (!duplicate) arrays.push_back({fields[k].name, {k}, fields[k].integer()});
    used[k] = true;
  }
  return arrays;
}

}  // namespace

void DumpCustomVtk::write_snapshot(const Snapshot& snap) {
  const auto& atoms = sim_.atoms;
  const std::size_t n = snap.particles.size();
  const std::string count = format_integer(static_cast<long long>(n));
  std::string text;
  text.reserve(96 * (n + 8));
  text += "# vtk DataFile Version 2.0\n";
  text += "dem_engine dump " + id() + " step " + format_integer(snap.step) + "\n";
  text += "ASCII\nDATASET POLYDATA\n";
  text += "POINTS " + count + " double\n";
  for (std::size_t i : snap.particles)
    text += format_number("%.10g", atoms.x[i].x) + " " + format_number("%.10g", atoms.x[i].y) +
            " " + format_number("%.10g", atoms.x[i].z) + "\n";
  text += "VERTICES " + count + " " + format_integer(2 * static_cast<long long>(n)) + "\n";
  for (std::size_t p = 0; p < n; ++p)
    text += "1 " + format_integer(static_cast<long long>(p)) + "\n";
  text += "POINT_DATA " + count + "\n";
  for (const VtkArray& array : vtk_arrays(fields_)) {
    if (array.fields.size() == 3) {
      text += "VECTORS " + array.name + " double\n";
    } else {
      text += "SCALARS " + array.name + (array.integer ? " int" : " double") + " 1\n";
      text += "LOOKUP_TABLE default\n";
    }
    for (std::size_t i : snap.particles) {
      for (std::size_t c = 0; c < array.fields.size(); ++c) {
        const std::size_t k = array.fields[c];
        const double value = dump_field_value(fields_[k], atoms, i, snap.compute_values[k]);
        if (c > 0) text += ' ';
        text += array.integer ? format_integer(static_cast<long long>(value))
                              : format_number("%.10g", value);
      }
      text += '\n';
    }
  }
  write_file_atomically(file_name(snap.step), text);
}

}  // namespace dem

#include "mesh/stl_io.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "deck/errors.h"
#include "mesh/triangle_geometry.h"

namespace dem {

namespace {

std::string lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string w;
  while (in >> w) words.push_back(w);
  return words;
}

[[noreturn]] void fail_at(const std::string& path, long line, const std::string& reason) {
  throw EngineError("STL file '" + path + "' line " + std::to_string(line) + ": " + reason);
}

double number_at(const std::string& word, const std::string& path, long line) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(word.c_str(), &end);
  if (word.empty() || *end != '\0' || errno != 0 || !std::isfinite(value))
    fail_at(path, line, "expected a number, got '" + word + "'");
  return value;
}

std::uint32_t read_u32_le(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

float read_f32_le(const unsigned char* p) {
  const std::uint32_t bits = read_u32_le(p);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

void write_u32_le(std::ostream& out, std::uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v & 0xff),
                              static_cast<unsigned char>((v >> 8) & 0xff),
                              static_cast<unsigned char>((v >> 16) & 0xff),
                              static_cast<unsigned char>((v >> 24) & 0xff)};
  out.write(reinterpret_cast<const char*>(b), 4);
}

void write_f32_le(std::ostream& out, double value) {
  const float f = static_cast<float>(value);
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  write_u32_le(out, bits);
}

std::vector<Triangle> parse_binary_stl(const std::string& bytes, const std::string& path) {
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::uint32_t n = read_u32_le(data + 80);
  std::vector<Triangle> tris(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const unsigned char* rec = data + 84 + 50 * static_cast<std::size_t>(t) + 12;  // skip normal
    for (int k = 0; k < 3; ++k) {
      const unsigned char* v = rec + 12 * k;
      tris[t].v[k] = Vec3{read_f32_le(v), read_f32_le(v + 4), read_f32_le(v + 8)};
      for (int d = 0; d < 3; ++d)
        if (!std::isfinite(tris[t].v[k][d]))
          throw EngineError("STL file '" + path + "' (binary): triangle " + std::to_string(t + 1) +
                            " has a non-finite coordinate");
    }
  }
  return tris;
}

}  // namespace

std::vector<Triangle> parse_ascii_stl(const std::string& text, const std::string& path) {
  // States of the facet grammar: solid > facet normal > outer loop > 3 vertex > endloop >
  // endfacet ... endsolid. The words are matched case-insensitively.
  enum class State { kOutside, kSolid, kFacet, kLoop, kEndLoop, kEndFacet };
  State state = State::kOutside;
  std::vector<Triangle> tris;
  Triangle current;
  int nvert = 0;
  long line_no = 0, facet_line = 0;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    ++line_no;
    const auto words = split_words(line);
    if (words.empty()) continue;
    const std::string key = lower(words[0]);
    switch (state) {
      case State::kOutside:
        if (key != "solid") fail_at(path, line_no, "expected 'solid', got '" + words[0] + "'");
        state = State::kSolid;
        break;
      case State::kSolid:
        if (key == "endsolid") {
          state = State::kOutside;
        } else if (key == "facet") {
          if (words.size() != 5 || lower(words[1]) != "normal")
            fail_at(path, line_no, "expected 'facet normal NX NY NZ'");
          for (int k = 2; k < 5; ++k) number_at(words[k], path, line_no);
          facet_line = line_no;
          state = State::kFacet;
        } else {
          fail_at(path, line_no, "expected 'facet' or 'endsolid', got '" + words[0] + "'");
        }
        break;
      case State::kFacet:
        if (key != "outer" || words.size() != 2 || lower(words[1]) != "loop")
          fail_at(path, line_no, "expected 'outer loop'");
        nvert = 0;
        state = State::kLoop;
        break;
      case State::kLoop:
        if (key != "vertex" || words.size() != 4)
          fail_at(path, line_no, "expected 'vertex X Y Z', got '" + line + "'");
        current.v[nvert] = Vec3{number_at(words[1], path, line_no),
                                number_at(words[2], path, line_no),
                                number_at(words[3], path, line_no)};
        if (++nvert == 3) state = State::kEndLoop;
        break;
      case State::kEndLoop:
        if (key != "endloop")
          fail_at(path, line_no, "expected 'endloop' after three vertices, got '" + words[0] + "'");
        state = State::kEndFacet;
        break;
      case State::kEndFacet:
        if (key != "endfacet")
          fail_at(path, line_no, "expected 'endfacet', got '" + words[0] + "'");
        tris.push_back(current);
        state = State::kSolid;
        break;
    }
  }
  if (state == State::kSolid)
    fail_at(path, line_no, "end of file before 'endsolid'");
  if (state != State::kOutside)
    fail_at(path, line_no,
            "end of file inside the facet that starts at line " + std::to_string(facet_line));
  if (tris.empty()) throw EngineError("STL file '" + path + "' contains no triangles");
  return tris;
}

std::vector<Triangle> read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw EngineError("cannot open STL file '" + path + "'");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  if (bytes.size() >= 84) {
    const std::uint32_t n = read_u32_le(data + 80);
    if (84 + 50 * static_cast<std::uint64_t>(n) == bytes.size()) {
      if (n == 0) throw EngineError("STL file '" + path + "' (binary) contains no triangles");
      return parse_binary_stl(bytes, path);
    }
  }
  std::size_t start = 0;
  while (start < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[start]))) ++start;
  if (lower(bytes.substr(start, 5)) != "solid") {
    std::string reason = "is neither ASCII STL (it does not start with 'solid') nor binary STL";
    if (bytes.size() >= 84)
      reason += " (its size " + std::to_string(bytes.size()) + " bytes does not match the " +
                std::to_string(read_u32_le(data + 80)) +
                " triangles of its header)";
    else
      reason += " (shorter than the 84-byte binary header)";
    throw EngineError("STL file '" + path + "' " + reason);
  }
  return parse_ascii_stl(bytes, path);
}

void write_stl_ascii(const std::string& path, const std::vector<Triangle>& triangles,
                     const std::string& solid_name) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw EngineError("cannot write STL file '" + path + "'");
  std::fprintf(f, "solid %s\n", solid_name.c_str());
  for (const Triangle& t : triangles) {
    const Vec3 n = triangle_normal(t.v[0], t.v[1], t.v[2]);
    std::fprintf(f, "  facet normal %.17g %.17g %.17g\n    outer loop\n", n.x, n.y, n.z);
    for (const Vec3& p : t.v) std::fprintf(f, "      vertex %.17g %.17g %.17g\n", p.x, p.y, p.z);
    std::fprintf(f, "    endloop\n  endfacet\n");
  }
  std::fprintf(f, "endsolid %s\n", solid_name.c_str());
  if (std::fclose(f) != 0) throw EngineError("cannot write STL file '" + path + "'");
}

void write_stl_binary(const std::string& path, const std::vector<Triangle>& triangles) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw EngineError("cannot write STL file '" + path + "'");
  std::string header(80, ' ');
  header.replace(0, 16, "binary STL mesh ");
  out.write(header.data(), 80);
  write_u32_le(out, static_cast<std::uint32_t>(triangles.size()));
  for (const Triangle& t : triangles) {
    const Vec3 n = triangle_normal(t.v[0], t.v[1], t.v[2]);
    write_f32_le(out, n.x);
    write_f32_le(out, n.y);
    write_f32_le(out, n.z);
    for (const Vec3& p : t.v) {
      write_f32_le(out, p.x);
      write_f32_le(out, p.y);
      write_f32_le(out, p.z);
    }
    const char attr[2] = {0, 0};
    out.write(attr, 2);
  }
  if (!out) throw EngineError("cannot write STL file '" + path + "'");
}

}  // namespace dem

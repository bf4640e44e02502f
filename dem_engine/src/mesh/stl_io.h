#pragma once
#include <array>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace dem {

struct Triangle {
  std::array<Vec3, 3> v;
};

// Reads an ASCII or binary STL file (m). A file is binary when its size is exactly
// 84 + 50 n bytes for the n triangles its header announces (binary files may also start with
// "solid"), otherwise it must be ASCII. Throws EngineError naming the file, and the line for
// ASCII syntax errors.
std::vector<Triangle> read_stl(const std::string& path);

// Parses ASCII STL text; `path` only names the source in error messages.
std::vector<Triangle> parse_ascii_stl(const std::string& text, const std::string& path);

// Writes triangles as ASCII STL (17 significant digits, so the round trip is exact) or as
// binary STL (32-bit floats). Normals are computed from the vertex order.
void write_stl_ascii(const std::string& path, const std::vector<Triangle>& triangles,
                     const std::string& solid_name = "mesh");
void write_stl_binary(const std::string& path, const std::vector<Triangle>& triangles);

}  // namespace dem

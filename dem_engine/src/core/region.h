#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace dem {

// Geometric region (LIGGGHTS `region ID style args [side in|out] [units box]`).
class Region {
 public:
  virtual ~Region() = default;
  // True when the point lies in the region (respecting `side`).
  bool inside(const Vec3& p) const { return side_in_ ? inside_shape(p) : !inside_shape(p); }
  // True when a sphere of radius r lies entirely in the region.
  virtual bool contains_sphere(const Vec3& p, double r) const = 0;
  virtual Vec3 extent_lo() const = 0;
  virtual Vec3 extent_hi() const = 0;
  virtual double volume() const = 0;
  bool side_in() const { return side_in_; }
  void set_side_in(bool in) { side_in_ = in; }

 protected:
  virtual bool inside_shape(const Vec3& p) const = 0;

 private:
  bool side_in_ = true;
};

// Parses the words after `region ID` (style and its arguments, plus side/units keywords).
// `box_lo`/`box_hi` replace INF/EDGE bounds. Throws EngineError on bad arguments.
std::unique_ptr<Region> make_region(const std::vector<std::string>& words, const Vec3& box_lo,
                                    const Vec3& box_hi, bool box_defined);

}  // namespace dem

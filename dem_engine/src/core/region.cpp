#include "core/region.h"

#include <cmath>
#include <limits>

#include "core/numbers.h"
#include "deck/errors.h"

namespace dem {
namespace {

constexpr double kInf = 1e30;  // INF bounds without a box

double bound(const std::string& word, double box_value, bool box_defined, double inf_sign,
             const std::string& what) {
  if (word == "INF" || word == "-INF") return word[0] == '-' ? -kInf : inf_sign * kInf;
  if (word == "EDGE") {
    if (!box_defined) throw EngineError("EDGE used for " + what + " before create_box");
    return box_value;
  }
  return parse_double(word, what);
}

class BlockRegion : public Region {
 public:
  BlockRegion(const Vec3& lo, const Vec3& hi) : lo_(lo), hi_(hi) {
    for (int k = 0; k < 3; ++k)
      if (!(lo_[k] < hi_[k])) throw EngineError("block region has lo >= hi");
  }
  bool contains_sphere(const Vec3& p, double r) const override {
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && p[k] - r >= lo_[k] && p[k] + r <= hi_[k];
    if (side_in()) return in;
    // Outside: the sphere must not touch the block.
    Vec3 q;
    for (int k = 0; k < 3; ++k) q[k] = std::fmax(lo_[k], std::fmin(p[k], hi_[k]));
    return norm2(q - p) >= r * r && !inside_shape(p);
  }
  Vec3 extent_lo() const override { return lo_; }
  Vec3 extent_hi() const override { return hi_; }
  double volume() const override {
    const Vec3 d = hi_ - lo_;
    return d.x * d.y * d.z;
  }

 protected:
  bool inside_shape(const Vec3& p) const override {
    return p.x >= lo_.x && p.x <= hi_.x && p.y >= lo_.y && p.y <= hi_.y && p.z >= lo_.z &&
           p.z <= hi_.z;
  }

 private:
  Vec3 lo_, hi_;
};

class CylinderRegion : public Region {
 public:
  CylinderRegion(int axis, double c1, double c2, double radius, double lo, double hi)
      : axis_(axis), c1_(c1), c2_(c2), radius_(radius), lo_(lo), hi_(hi) {
    if (!(radius_ > 0)) throw EngineError("cylinder region radius must be > 0");
    if (!(lo_ < hi_)) throw EngineError("cylinder region has lo >= hi");
  }
  bool contains_sphere(const Vec3& p, double r) const override {
    const double rad = radial(p);
    const double a = p[axis_];
    if (side_in()) return rad + r <= radius_ && a - r >= lo_ && a + r <= hi_;
    return rad - r >= radius_ || a + r <= lo_ || a - r >= hi_;
  }
  Vec3 extent_lo() const override { return corner(-1.0, lo_); }
  Vec3 extent_hi() const override { return corner(1.0, hi_); }
  double volume() const override { return M_PI * radius_ * radius_ * (hi_ - lo_); }

 protected:
  bool inside_shape(const Vec3& p) const override {
    return radial(p) <= radius_ && p[axis_] >= lo_ && p[axis_] <= hi_;
  }

 private:
  double radial(const Vec3& p) const {
    const int a = (axis_ + 1) % 3, b = (axis_ + 2) % 3;
    // LIGGGHTS: for dim x the centre is (y, z); for y it is (x, z); for z it is (x, y).
    const double u = p[axis_ == 1 ? 0 : a] - c1_;
    const double w = p[axis_ == 1 ? 2 : b] - c2_;
    return std::sqrt(u * u + w * w);
  }
  Vec3 corner(double sign, double axial) const {
    Vec3 c;
    c[axis_] = axial;
    const int first = axis_ == 0 ? 1 : 0;
    const int second = axis_ == 2 ? 1 : 2;
    c[first] = c1_ + sign * radius_;
    c[second] = c2_ + sign * radius_;
    return c;
  }
  int axis_;
  double c1_, c2_, radius_, lo_, hi_;
};

}  // namespace

std::unique_ptr<Region> make_region(const std::vector<std::string>& words, const Vec3& box_lo,
                                    const Vec3& box_hi, bool box_defined) {
  if (words.empty()) throw EngineError("missing region style");
  const std::string& style = words[0];
  std::size_t used = 0;
  std::unique_ptr<Region> region;
  if (style == "block") {
    require_args(words, 7, "region ID block xlo xhi ylo yhi zlo zhi [side in|out] [units box]");
    Vec3 lo, hi;
    const char* names[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      lo[k] = bound(words[1 + 2 * k], box_lo[k], box_defined, -1.0, std::string(names[k]) + "lo");
      hi[k] = bound(words[2 + 2 * k], box_hi[k], box_defined, 1.0, std::string(names[k]) + "hi");
    }
    region = std::make_unique<BlockRegion>(lo, hi);
    used = 7;
  } else if (style == "cylinder") {
    require_args(words, 7, "region ID cylinder x|y|z c1 c2 radius lo hi [side in|out] [units box]");
    const std::string& dim = words[1];
    if (dim != "x" && dim != "y" && dim != "z")
      throw EngineError("cylinder axis must be x, y or z, got '" + dim + "'");
    const int axis = dim == "x" ? 0 : (dim == "y" ? 1 : 2);
    const double c1 = parse_double(words[2], "cylinder c1");
    const double c2 = parse_double(words[3], "cylinder c2");
    const double r = parse_double(words[4], "cylinder radius");
    const double lo = bound(words[5], box_lo[axis], box_defined, -1.0, "cylinder lo");
    const double hi = bound(words[6], box_hi[axis], box_defined, 1.0, "cylinder hi");
    region = std::make_unique<CylinderRegion>(axis, c1, c2, r, lo, hi);
    used = 7;
  } else {
    throw EngineError("unknown region style '" + style + "' (supported: block, cylinder)");
  }
  for (std::size_t i = used; i < words.size(); i += 2) {
    if (i + 1 >= words.size()) throw EngineError("region keyword '" + words[i] + "' needs a value");
    const std::string& key = words[i];
    const std::string& value = words[i + 1];
    if (key == "side") {
      if (value != "in" && value != "out") throw EngineError("region side must be in or out");
      region->set_side_in(value == "in");
    } else if (key == "units") {
      if (value != "box") throw EngineError("only 'units box' is supported for regions");
    } else {
      throw EngineError("unknown region keyword '" + key + "'");
    }
  }
  return region;
}

}  // namespace dem

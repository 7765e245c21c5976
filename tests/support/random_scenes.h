#pragma once
// Seeded random *valid* scenes for the property tests: a sphere or box (random transform),
// a random base material per channel (albedo 0..1, g in (-0.9, 0.9), ior 1..1.6), half of
// them with a random heterogeneous material set, one to three lights of every kind, a
// camera looking at the object, lpv grid 8..16 with either scheme and fixed or auto steps.
// Built as scene JSON and read by parseScene, so every scene passes the scene contract
// (a generator drifting out of the accepted ranges fails loudly there, not silently).
#include <openvdb/openvdb.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include "monte_carlo.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"

namespace sslpv::test {

struct RandomScene {
  Scene scene;
  /// A heterogeneous material set in the object's rest space (scene units), or null.
  std::shared_ptr<const MaterialSet> set;
  std::string json;  ///< the scene as generated, for failure messages
};

class SceneRandom {
 public:
  explicit SceneRandom(std::uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  /// An albedo in [0, 1] that is exactly 0 or 1 a tenth of the time each (the edges of the range).
  double albedo() {
    const double u = uniform(0.0, 1.0);
    return u < 0.1 ? 0.0 : u > 0.9 ? 1.0 : uniform(0.0, 1.0);
  }
  /// Three draws for one vector, made in a fixed order. Function arguments are evaluated in
  /// an unspecified order (GCC right to left, clang left to right), so drawing inside one
  /// call's argument list gave each compiler a different scene for the same seed. The last
  /// component is drawn first, as GCC did, so every seed keeps the scene its tests were
  /// written against.
  template <typename Draw>
  auto triple(Draw draw) {
    const auto z = draw(), y = draw(), x = draw();
    return std::array<decltype(z), 3>{x, y, z};
  }
  std::mt19937_64& engine() { return rng_; }

 private:
  std::mt19937_64 rng_;
};

inline std::string vec3Json(double x, double y, double z) {
  std::ostringstream s;
  s.precision(17);
  s << "[" << x << ", " << y << ", " << z << "]";
  return s.str();
}

/// Random σt/σs/g voxels (and sometimes a g grid) within `extent` of the rest-space origin.
inline std::shared_ptr<const MaterialSet> randomMaterialSet(SceneRandom& r, double extent) {
  auto set = emptyMaterialSet();
  const double voxel = extent / r.integer(3, 8);
  auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  if (r.chance(0.5)) transform->postRotate(r.uniform(0.0, 3.0), openvdb::math::Y_AXIS);
  set->sigmaT->setTransform(transform);
  set->sigmaS->setTransform(transform->copy());
  const bool withG = r.chance(0.5);
  if (withG) {
    set->g = openvdb::FloatGrid::create(0.0f);
    set->g->setName("g");
    set->g->setTransform(transform->copy());
  }
  const int reach = int(std::ceil(extent / voxel));
  const int count = r.integer(1, 300);
  for (int k = 0; k < count; ++k) {
    const auto cell = r.triple([&] { return r.integer(-reach, reach); });
    const openvdb::Coord ijk(cell[0], cell[1], cell[2]);
    openvdb::Vec3s t, s;
    for (int c = 0; c < 3; ++c) {
      t[c] = float(r.logUniform(0.01, 50.0));
      s[c] = float(r.albedo()) * t[c];
    }
    set->sigmaT->tree().setValueOn(ijk, t);
    set->sigmaS->tree().setValueOn(ijk, s);
    if (withG) set->g->tree().setValueOn(ijk, float(r.uniform(-0.9, 0.9)));
  }
  return set;
}

/// Boundary indices drawn from: the renderers build calibration tables per ior (~0.1 s
/// each), so a continuous draw would spend most of a property test building tables.
inline constexpr double kIors[] = {1.0, 1.1, 1.25, 1.33, 1.4, 1.5, 1.6};

/// A random valid scene whose camera renders `side` x `side` pixels.
inline RandomScene randomScene(std::uint64_t seed, int side) {
  SceneRandom r(seed);
  std::ostringstream j;
  j.precision(17);
  double size = 0.0;  // the object's half extent in rest space
  j << "{\"units\": \"mm\", \"mesh\": ";
  if (r.chance(0.5)) {
    size = r.uniform(2.0, 10.0);
    j << "{\"primitive\": \"sphere\", \"center\": [0, 0, 0], \"radius\": " << size << "}";
  } else {
    const double hx = r.uniform(2.0, 10.0), hy = r.uniform(2.0, 10.0), hz = r.uniform(2.0, 10.0);
    size = std::max({hx, hy, hz});
    j << "{\"primitive\": \"box\", \"min\": " << vec3Json(-hx, -hy, -hz) << ", \"max\": " << vec3Json(hx, hy, hz)
      << "}";
  }
  const double scale = r.chance(0.5) ? r.logUniform(0.5, 2.0) : 1.0;
  const double cx = r.uniform(-5, 5), cy = r.uniform(-5, 5), cz = r.uniform(-5, 5);
  const auto rotation = r.triple([&] { return r.uniform(-180, 180); });
  j << ", \"transform\": {\"translate\": " << vec3Json(cx, cy, cz)
    << ", \"rotate_deg\": " << vec3Json(rotation[0], rotation[1], rotation[2])
    << ", \"scale\": " << scale << "}";
  const double worldSize = size * scale * std::sqrt(3.0);  // bounding radius

  j << ", \"material\": {\"base\": {";
  std::ostringstream st, ss;
  for (int c = 0; c < 3; ++c) {
    const double t = r.logUniform(0.02, 30.0), a = r.albedo();
    st << (c ? ", " : "") << t;
    ss << (c ? ", " : "") << a * t;
  }
  j << "\"sigma_t\": [" << st.str() << "], \"sigma_s\": [" << ss.str() << "], \"g\": " << r.uniform(-0.9, 0.9)
    << "}, \"ior\": " << kIors[r.integer(0, int(std::size(kIors)) - 1)] << "}";

  // Lights and camera around the object's centre, outside its bounding sphere.
  j << ", \"lights\": [";
  const int lights = r.integer(1, 3);
  for (int l = 0; l < lights; ++l) {
    const double theta = r.uniform(0.0, 6.283185307179586), phi = r.uniform(-1.2, 1.2);
    const double d = worldSize * r.uniform(2.5, 6.0);
    const double x = d * std::cos(phi) * std::cos(theta), y = d * std::sin(phi), z = d * std::cos(phi) * std::sin(theta);
    const double power = r.logUniform(10.0, 1e5);
    if (l) j << ", ";
    switch (r.integer(0, 2)) {
      case 0: {
        const double blue = r.uniform(0, 1), green = r.uniform(0, 1);  // as GCC drew them (see triple)
        j << "{\"type\": \"point\", \"position\": " << vec3Json(cx + x, cy + y, cz + z) << ", \"intensity\": "
          << vec3Json(power, power * green, power * blue) << "}";
        break;
      }
      case 1:
        j << "{\"type\": \"spot\", \"position\": " << vec3Json(cx + x, cy + y, cz + z) << ", \"direction\": " << vec3Json(-x, -y, -z)
          << ", \"fov_deg\": " << r.uniform(10.0, 120.0) << ", \"intensity\": " << vec3Json(power, power, power) << "}";
        break;
      default:
        j << "{\"type\": \"directional\", \"direction\": " << vec3Json(-x, -y, -z) << ", \"irradiance\": "
          << vec3Json(power * 1e-3, power * 1e-3, power * 1e-3) << "}";
    }
  }
  const double theta = r.uniform(0.0, 6.283185307179586), phi = r.uniform(-1.2, 1.2);
  const double d = worldSize * r.uniform(2.0, 3.5);
  j << "], \"camera\": {\"position\": "
    << vec3Json(cx + d * std::cos(phi) * std::cos(theta), cy + d * std::sin(phi),
                cz + d * std::cos(phi) * std::sin(theta))
    << ", \"target\": " << vec3Json(cx, cy, cz) << ", \"fov_y_deg\": " << r.uniform(30.0, 60.0) << ", \"width\": " << side
    << ", \"height\": " << side << "}";
  j << ", \"lpv\": {\"resolution\": " << r.integer(8, 16) << ", \"steps\": ";
  if (r.chance(0.5))
    j << "\"auto\"";
  else
    j << r.integer(1, 40);
  j << ", \"shadow_map\": " << r.integer(16, 64) << ", \"scheme\": \"" << (r.chance(0.7) ? "calibrated" : "seed")
    << "\"}}";

  RandomScene out;
  out.json = j.str();
  out.scene = parseScene(out.json, "random" + std::to_string(seed) + ".json");
  if (r.chance(0.5)) out.set = randomMaterialSet(r, size);
  return out;
}

}  // namespace sslpv::test

#pragma once
// Random vectors drawn in a fixed order, so a seed gives the same test case under every
// compiler. Written as `Vec(d(rng), d(rng), d(rng))` the draws' order is unspecified (GCC
// evaluates arguments right to left, clang left to right), and a failure seen in the clang
// build could not be replayed under GCC. The last component is drawn first, the order GCC
// used, so every existing seed keeps the case its test was written against under GCC.

namespace sslpv::test {

/// Vec(x, y, z) from three calls of `draw()`: z, then y, then x.
template <typename Vec, typename Draw>
Vec drawVec3(Draw&& draw) {
  const auto z = draw();
  const auto y = draw();
  const auto x = draw();
  return Vec(x, y, z);
}

/// Vec(dx(engine), dy(engine), dz(engine)), drawn z, then y, then x.
template <typename Vec, typename DistX, typename DistY, typename DistZ, typename Engine>
Vec drawVec3(DistX& dx, DistY& dy, DistZ& dz, Engine& engine) {
  const auto z = dz(engine);
  const auto y = dy(engine);
  const auto x = dx(engine);
  return Vec(x, y, z);
}

/// Each component from `dist(engine)`, drawn z, then y, then x.
template <typename Vec, typename Dist, typename Engine>
Vec drawVec3(Dist& dist, Engine& engine) {
  return drawVec3<Vec>(dist, dist, dist, engine);
}

}  // namespace sslpv::test

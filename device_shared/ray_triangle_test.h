// The watertight ray-triangle crossing test, shared verbatim by the CPU ray caster
// (volume/scene/ray_scene.cpp) and the GPU resolve passes (shaders/ray_triangle_pick.glsl), so
// that both pick the same triangle where a ray passes within rounding of a shared edge.
// Written in the common subset of C++17 and GLSL 4.60.
//
// Each edge's side is the sign of the triple product [d, a - o, b - o] computed with the
// edge's endpoints in ascending vertex-index order and negated for the other direction:
// the two triangles sharing an edge of a welded mesh see exactly opposite values, so a
// ray can fall through neither. The products are spelled out (not GLSL's dot()/cross(),
// whose association the driver chooses) and `precise` on the GPU; the C++ build uses
// -ffp-contract=off (CMakeLists.txt, sslpv_tuning), so both round identically.
#ifndef SSLPV_RAY_TRIANGLE_TEST_H
#define SSLPV_RAY_TRIANGLE_TEST_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/vec3.hpp>
#define SSLPV_RT_UINT std::uint32_t
#define SSLPV_RT_FN inline
#define SSLPV_RT_PRECISE
namespace sslpv::raytri {
using vec3 = glm::vec3;
#else
#define SSLPV_RT_UINT uint
#define SSLPV_RT_FN
#define SSLPV_RT_PRECISE precise
#endif

/// Which side of the edge (ia, pa) -> (ib, pb) the ray origin o + t d passes; exactly
/// the negation of the reversed edge's value.
SSLPV_RT_FN float rayEdgeSide(vec3 o, vec3 d, SSLPV_RT_UINT ia, vec3 pa, SSLPV_RT_UINT ib, vec3 pb) {
  bool swapped = ia > ib;
  vec3 lo = swapped ? pb : pa;
  vec3 hi = swapped ? pa : pb;
  SSLPV_RT_PRECISE vec3 a = lo - o;
  SSLPV_RT_PRECISE vec3 b = hi - o;
  SSLPV_RT_PRECISE float side =
      d.x * (a.y * b.z - a.z * b.y) + d.y * (a.z * b.x - a.x * b.z) + d.z * (a.x * b.y - a.y * b.x);
  return swapped ? -side : side;
}

/// The ray's line crosses triangle (i0, i1, i2) when the three edge signs agree (either
/// winding: back faces count, as a nearest hit may be one). Whether the crossing lies
/// ahead of the origin is the caller's test.
SSLPV_RT_FN bool rayCrossesTriangle(vec3 o, vec3 d, SSLPV_RT_UINT i0, vec3 p0, SSLPV_RT_UINT i1, vec3 p1,
                                    SSLPV_RT_UINT i2, vec3 p2) {
  float e0 = rayEdgeSide(o, d, i0, p0, i1, p1);
  float e1 = rayEdgeSide(o, d, i1, p1, i2, p2);
  float e2 = rayEdgeSide(o, d, i2, p2, i0, p0);
  bool nonNegative = e0 >= 0.0f && e1 >= 0.0f && e2 >= 0.0f;
  bool nonPositive = e0 <= 0.0f && e1 <= 0.0f && e2 <= 0.0f;
  // All zero: a degenerate triangle or a ray in its plane, which no ray caster hits.
  return (nonNegative || nonPositive) && !(e0 == 0.0f && e1 == 0.0f && e2 == 0.0f);
}

#ifdef __cplusplus
}  // namespace sslpv::raytri
#endif

#endif  // SSLPV_RAY_TRIANGLE_TEST_H

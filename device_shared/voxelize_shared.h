// Voxelization by nearest-triangle distance and column parity, shared verbatim by the CPU
// twin (volume/lpv/voxelize_parity.cpp) and the GPU kernels (shaders/voxelize_*.comp): the
// constants, the push-constant record and every function that turns geometry into a
// number the two sides must agree on. Written in the common subset of C++17 and GLSL 4.60
// (scalar and vec3 float arithmetic, out parameters through SSLPV_VOX_OUT).
//
// All geometry is in continuous grid coordinates (cell (i,j,k) spans [i, i+1)), so
// distances are in cells. Per cell the GPU keeps one 32-bit word, the atomic minimum of
//   (quantized distance << 18) | (octant-encoded |normal|)
// over the triangles within SSLPV_VOX_WHOLE_CELL of its centre: the nearest triangle's
// distance and the direction from it (the distance field's gradient up to sign, which the
// plane-cube coverage does not need). Minimum is order-independent, so the result does
// not depend on how threads interleave.
#ifndef SSLPV_VOXELIZE_SHARED_H
#define SSLPV_VOXELIZE_SHARED_H

/// Beyond this distance (cells) from the surface the cell is wholly on one side for any
/// normal (sqrt(3)/2 = 0.866025..): volume/lpv/voxelize.cpp's wholeCellDistance.
#define SSLPV_VOX_WHOLE_CELL 0.8661f
/// Bits of the packed word: distance in [0, WHOLE_CELL) in 14 bits (5.3e-5 cells a
/// step), then two 9-bit coordinates of |normal| on the positive octant.
#define SSLPV_VOX_DISTANCE_STEPS 16383.0f
#define SSLPV_VOX_NORMAL_STEPS 511.0f
/// The initial value of a cell no triangle came near.
#define SSLPV_VOX_EMPTY 0xFFFFFFFFu
/// Column parity uses exact fixed-point x, y (1/4096 cell) so that an edge shared by two
/// triangles is counted by exactly one of them; coordinates are clamped to +-2^18 cells
/// around the frame so that differences fit in 31 bits and products in 62.
#define SSLPV_VOX_FIXED_SCALE 4096.0f
#define SSLPV_VOX_MAX_COORD 262143.0f
/// Workgroup sizes of the triangle and the cell kernel.
#define SSLPV_VOX_TRIANGLE_GROUP 64
#define SSLPV_VOX_CELL_GROUP 64

#ifdef __cplusplus
#include <cmath>
#include <cstddef>
#include <cstdint>
#define SSLPV_VOX_UINT std::uint32_t
#define SSLPV_VOX_FN inline
#define SSLPV_VOX_OUT(type) type&
#else
#define SSLPV_VOX_UINT uint
#define SSLPV_VOX_FN
#define SSLPV_VOX_OUT(type) out type
#endif

#ifndef SSLPV_DECLARE_FIELD
#define SSLPV_DECLARE_FIELD(type, name) type name;
#endif

/// Push constants of both voxelization kernels (4-byte scalars only, so C++ and GLSL lay
/// them out alike).
#define SSLPV_VOXELIZE_PUSH_FIELDS(X)                                                    \
  X(float, originX)         /* world position of the frame's min corner, as float */  \
  X(float, originY)                                                                   \
  X(float, originZ)                                                                   \
  X(float, inverseCellSize) /* world -> grid scale */                                 \
  X(int, dimsX)                                                                       \
  X(int, dimsY)                                                                       \
  X(int, dimsZ)                                                                       \
  X(int, wordsPerColumn)    /* parity words per (x, y) column: ceil(dimsZ / 32) */    \
  X(SSLPV_VOX_UINT, triangleCount)                                                    \
  X(SSLPV_VOX_UINT, threadCount) /* triangle kernel: invocations dispatched (the stride) */

#ifdef __cplusplus
namespace sslpv::vox {

struct VoxelizePush {
  SSLPV_VOXELIZE_PUSH_FIELDS(SSLPV_DECLARE_FIELD)
};
static_assert(sizeof(VoxelizePush) == 10 * 4, "VoxelizePush must be 4-byte scalars only");
static_assert(offsetof(VoxelizePush, dimsX) == 4 * 4 && offsetof(VoxelizePush, threadCount) == 9 * 4,
              "VoxelizePush field order");

// The shared functions must round as the GPU does: no fused multiply-adds, which
// -march=native would otherwise let GCC contract from a*b+c. Lavapipe evaluates the same
// SPIR-V unfused: GPU and twin agree bit for bit (tests/gpu/gpu_voxelize_test.cpp counts any
// difference). Code that includes this header after its own push_options may set the
// same flag so that these functions inline into it.
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")

/// The GLSL vec3 subset the shared functions use.
struct vec3 {
  float x = 0.0f, y = 0.0f, z = 0.0f;
  vec3() = default;
  explicit vec3(float s) : x(s), y(s), z(s) {}
  vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
};
inline vec3 operator+(vec3 a, vec3 b) { return vec3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline vec3 operator-(vec3 a, vec3 b) { return vec3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline vec3 operator*(vec3 a, float s) { return vec3(a.x * s, a.y * s, a.z * s); }
inline vec3 operator*(float s, vec3 a) { return vec3(a.x * s, a.y * s, a.z * s); }
inline vec3 operator/(vec3 a, float s) { return vec3(a.x / s, a.y / s, a.z / s); }
inline float min(float a, float b) { return b < a ? b : a; }
inline float max(float a, float b) { return a < b ? b : a; }
inline float abs(float a) { return std::fabs(a); }
inline float sqrt(float a) { return std::sqrt(a); }
inline float floor(float a) { return std::floor(a); }
inline float clamp(float v, float lo, float hi) { return min(max(v, lo), hi); }
inline vec3 abs(vec3 a) { return vec3(std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)); }
inline vec3 min(vec3 a, vec3 b) { return vec3(min(a.x, b.x), min(a.y, b.y), min(a.z, b.z)); }
inline vec3 max(vec3 a, vec3 b) { return vec3(max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)); }
#endif

// GLSL's dot() and cross() may be evaluated with a different association or fused; these
// spell out one order for both sides.
SSLPV_VOX_FN float vox_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SSLPV_VOX_FN vec3 vox_cross(vec3 a, vec3 b) {
  return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/// World position -> continuous grid coordinates.
SSLPV_VOX_FN vec3 vox_toGrid(vec3 world, vec3 origin, float inverseCellSize) {
  return (world - origin) * inverseCellSize;
}

/// A triangle prepared for many distance queries: everything that does not depend on the
/// query point, computed once per triangle (vox_setupTriangle).
struct VoxTriangle {
  vec3 a;
  vec3 b;
  vec3 c;
  vec3 ab;
  vec3 bc;
  vec3 ca;
  vec3 normal;  ///< unit face normal (zero for a sliver)
  vec3 dualB;   ///< dot(q - a, dualB), dot(q - a, dualC): barycentric weights of b and c of
  vec3 dualC;   ///< the projection q of a point onto the plane
  float inverseAB2;  ///< 1 / |edge|^2, 0 for a zero-length edge
  float inverseBC2;
  float inverseCA2;
  bool hasFace;  ///< false for slivers and segments: the distance is the edges' alone
};

SSLPV_VOX_FN float vox_inverseOrZero(float x) { return x > 0.0f ? 1.0f / x : 0.0f; }

SSLPV_VOX_FN void vox_setupTriangle(vec3 a, vec3 b, vec3 c, SSLPV_VOX_OUT(VoxTriangle) t) {
  t.a = a;
  t.b = b;
  t.c = c;
  t.ab = b - a;
  t.bc = c - b;
  t.ca = a - c;
  vec3 ac = c - a;
  vec3 n = vox_cross(t.ab, ac);
  float area2 = vox_dot(n, n);
  float lengthAB2 = vox_dot(t.ab, t.ab);
  float lengthAC2 = vox_dot(ac, ac);
  t.inverseAB2 = vox_inverseOrZero(lengthAB2);
  t.inverseBC2 = vox_inverseOrZero(vox_dot(t.bc, t.bc));
  t.inverseCA2 = vox_inverseOrZero(lengthAC2);
  // Below this the face's plane is numerically meaningless; its edges still are.
  t.hasFace = area2 > 1e-12f * lengthAB2 * lengthAC2;
  float inverseArea2 = t.hasFace ? 1.0f / area2 : 0.0f;
  t.normal = t.hasFace ? n / sqrt(area2) : vec3(0.0f);
  t.dualB = vox_cross(ac, n) * inverseArea2;
  t.dualC = vox_cross(n, t.ab) * inverseArea2;
}

/// Offset from the nearest point of the segment (origin, origin + edge) to a point at
/// `fromOrigin` relative to its origin.
SSLPV_VOX_FN vec3 vox_segmentOffset(vec3 fromOrigin, vec3 edge, float inverseLength2) {
  float s = clamp(vox_dot(fromOrigin, edge) * inverseLength2, 0.0f, 1.0f);
  return fromOrigin - edge * s;
}

/// Exact distance from p to the triangle and the distance field's gradient direction at p
/// up to sign: the face normal where p projects inside the face (also when p lies on it),
/// else the direction from the nearest point of the nearest edge. Branches only on whether
/// the projection is inside, so SIMD lanes stay together.
SSLPV_VOX_FN void vox_pointTriangle(vec3 p, VoxTriangle t, SSLPV_VOX_OUT(float) dist, SSLPV_VOX_OUT(vec3) dir) {
  vec3 ap = p - t.a;
  float v = vox_dot(ap, t.dualB);
  float w = vox_dot(ap, t.dualC);
  if (t.hasFace && v >= 0.0f && w >= 0.0f && v + w <= 1.0f) {
    dist = abs(vox_dot(ap, t.normal));
    dir = t.normal;
    return;
  }
  vec3 off = vox_segmentOffset(ap, t.ab, t.inverseAB2);
  float best = vox_dot(off, off);
  vec3 offBC = vox_segmentOffset(p - t.b, t.bc, t.inverseBC2);
  float d2 = vox_dot(offBC, offBC);
  if (d2 < best) {
    best = d2;
    off = offBC;
  }
  vec3 offCA = vox_segmentOffset(p - t.c, t.ca, t.inverseCA2);
  d2 = vox_dot(offCA, offCA);
  if (d2 < best) {
    best = d2;
    off = offCA;
  }
  dist = sqrt(best);
  dir = dist > 0.0f ? off / dist : (t.hasFace ? t.normal : vec3(1.0f, 0.0f, 0.0f));
}

/// The packed word of a cell whose centre is `dist` (< WHOLE_CELL) from a triangle with
/// gradient direction `dir`: distance in the high bits (the atomic minimum picks the
/// nearest triangle), |dir| projected on the octant's plane u + v + w = 1 in the low bits.
SSLPV_VOX_FN SSLPV_VOX_UINT vox_pack(float dist, vec3 dir) {
  float q = min(floor(dist * (SSLPV_VOX_DISTANCE_STEPS / SSLPV_VOX_WHOLE_CELL)), SSLPV_VOX_DISTANCE_STEPS - 1.0f);
  vec3 a = abs(dir);
  float sum = a.x + a.y + a.z;
  // Divisions, not a product with 1 / sum: a direction on a diagonal then lands exactly on
  // a rounding tie of the octant grid (u = 0.5), where a reciprocal that the device rounds
  // differently from the host would pick the other side.
  float u = sum > 0.0f ? a.x / sum : 0.0f;
  float v = sum > 0.0f ? a.y / sum : 0.0f;
  SSLPV_VOX_UINT qu = SSLPV_VOX_UINT(floor(u * SSLPV_VOX_NORMAL_STEPS + 0.5f));
  SSLPV_VOX_UINT qv = SSLPV_VOX_UINT(floor(v * SSLPV_VOX_NORMAL_STEPS + 0.5f));
  return (SSLPV_VOX_UINT(q) << 18u) | (qu << 9u) | qv;
}

/// The distance (cells, mid-step) and unit |normal| a packed word stands for.
SSLPV_VOX_FN void vox_unpack(SSLPV_VOX_UINT packed, SSLPV_VOX_OUT(float) dist, SSLPV_VOX_OUT(vec3) normal) {
  dist = (float(packed >> 18u) + 0.5f) * (SSLPV_VOX_WHOLE_CELL / SSLPV_VOX_DISTANCE_STEPS);
  float u = float((packed >> 9u) & 511u) / SSLPV_VOX_NORMAL_STEPS;
  float v = float(packed & 511u) / SSLPV_VOX_NORMAL_STEPS;
  vec3 a = vec3(u, v, max(0.0f, 1.0f - u - v));
  normal = a / sqrt(vox_dot(a, a));
}

/// Second mixed divided difference of max(0, r)^3 with steps a1 <= a2, i.e.
/// [f(r) - f(r-a1) - f(r-a2) + f(r-a1-a2)] / (a1 a2), written so that nothing cancels
/// catastrophically as a1 or a2 go to 0 (float has no room for the raw inclusion-exclusion
/// over the cube's corners with a tiny normal component, which the double CPU version uses).
SSLPV_VOX_FN float vox_cubicDifference2(float r, float a1, float a2) {
  if (r <= 0.0f) return 0.0f;
  if (r <= a1) return r * r * r / (a1 * a2);
  float r1 = r - a1;
  float first = r * r + r * r1 + r1 * r1;  // [r^3 - (r-a1)^3] / a1
  if (r <= a2) return first / a2;
  if (r <= a1 + a2) {
    float r2 = r - a2;  // in (0, a1]
    return (first - r2 * r2 * r2 / a1) / a2;
  }
  return 6.0f * r - 3.0f * (a1 + a2);
}

/// Fraction of the unit cube [0,1]^3 with a.v < level, a sorted a1 <= a2 <= a3, a3 > 0.
SSLPV_VOX_FN float vox_cubeFractionBelow(float a1, float a2, float a3, float level) {
  return (vox_cubicDifference2(level, a1, a2) - vox_cubicDifference2(level - a3, a1, a2)) / (6.0f * a3);
}

/// Float twin of sslpv::planeCubeCoverage (volume/lpv/voxelize.cpp): the exact fraction of a
/// cell behind the plane at signed distance `distanceCells` (negative: centre inside) with
/// unit normal `normal`.
SSLPV_VOX_FN float vox_planeCubeCoverage(float distanceCells, vec3 normal) {
  vec3 n = abs(normal);
  float a3 = max(max(n.x, n.y), n.z);
  float a1 = min(min(n.x, n.y), n.z);
  float a2 = max(min(n.x, n.y), min(max(n.x, n.y), n.z));  // the median
  float halfExtent = 0.5f * (a1 + a2 + a3);
  float level = halfExtent - distanceCells;
  if (level <= 0.0f) return 0.0f;
  if (level >= 2.0f * halfExtent) return 1.0f;
  float fraction = level <= halfExtent ? vox_cubeFractionBelow(a1, a2, a3, level)
                                       : 1.0f - vox_cubeFractionBelow(a1, a2, a3, 2.0f * halfExtent - level);
  return clamp(fraction, 0.0f, 1.0f);
}

/// Coverage of a cell from its packed word and whether its centre is inside the mesh.
SSLPV_VOX_FN float vox_cellCoverage(SSLPV_VOX_UINT packed, bool inside) {
  if (packed == SSLPV_VOX_EMPTY) return inside ? 1.0f : 0.0f;
  float dist;
  vec3 normal;
  vox_unpack(packed, dist, normal);
  return vox_planeCubeCoverage(inside ? -dist : dist, normal);
}

/// Fixed-point column coordinate of a grid coordinate: cell centres x + 0.5 land on the
/// integers x * FIXED_SCALE, so the column lines are exact.
SSLPV_VOX_FN int vox_fixed(float g) {
  return int(floor(clamp(g - 0.5f, -SSLPV_VOX_MAX_COORD, SSLPV_VOX_MAX_COORD) * SSLPV_VOX_FIXED_SCALE + 0.5f));
}

/// The cell whose parity bit a crossing of column (px, py) with triangle abc toggles: the
/// first cell whose centre lies above the crossing (a centre exactly on it is outside);
/// cells from there up see one more crossing below them. abc are grid coordinates.
SSLPV_VOX_FN int vox_crossingCell(vec3 a, vec3 b, vec3 c, float px, float py) {
  vec3 n = vox_cross(b - a, c - a);
  float zLo = min(min(a.z, b.z), c.z);
  float zHi = max(max(a.z, b.z), c.z);
  float z = n.z != 0.0f ? a.z - (n.x * (px - a.x) + n.y * (py - a.y)) / n.z : 0.5f * (zLo + zHi);
  // The column passes through the triangle, so the crossing lies within its z range.
  z = clamp(z, zLo, zHi);
  return int(floor(clamp(z, -1.0f, SSLPV_VOX_MAX_COORD) + 0.5f));
}

#ifdef __cplusplus
#pragma GCC pop_options
}  // namespace sslpv::vox
#endif

#endif

#version 460
// Per triangle: scatter the packed nearest distance + direction to every cell centre
// within SSLPV_VOX_WHOLE_CELL (atomic minimum), and toggle the crossing bit of every
// z column its xy projection covers (atomic xor). The CPU twin is
// volume/lpv/voxelize_parity.cpp (scatterDistance, scatterParity, edgeSign). Both enumerate
// a superset of the cells and columns the exact tests keep (any superset gives the same
// minimum and the same crossings); every value comes from device_shared/voxelize_shared.h.
#extension GL_GOOGLE_include_directive : require
#include "device_shared/voxelize_shared.h"

layout(local_size_x = SSLPV_VOX_TRIANGLE_GROUP) in;

layout(push_constant) uniform PushBlock { SSLPV_VOXELIZE_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;
layout(std430, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 2) buffer Nearest { uint nearest[]; };
layout(std430, binding = 3) buffer Parity { uint parity[]; };

// Margin of the candidate enumeration over the exact distance test (as the twin's): an
// absolute part for coordinates near the grid and a relative one for far-away vertices.
float enumerationReach(vec3 a, vec3 b, vec3 c) {
  vec3 m = max(max(abs(a), abs(b)), abs(c));
  return SSLPV_VOX_WHOLE_CELL + 1e-3 + 1e-6 * max(max(m.x, m.y), m.z);
}

// Permutations between xyz and (u, v, w) with w the normal's dominant axis and
// u = w + 1, v = w + 2 (mod 3): swizzles rather than dynamically indexed components,
// which compilers tend to spill to memory.
vec3 toUVW(vec3 x, int w) { return w == 2 ? x : (w == 0 ? x.yzx : x.zxy); }
ivec3 toUVW(ivec3 x, int w) { return w == 2 ? x : (w == 0 ? x.yzx : x.zxy); }
vec3 fromUVW(vec3 x, int w) { return w == 2 ? x : (w == 0 ? x.zxy : x.yzx); }
ivec3 fromUVW(ivec3 x, int w) { return w == 2 ? x : (w == 0 ? x.zxy : x.yzx); }

// One invocation walks the triangle's box column by column along the normal's dominant
// axis w, visiting only the slab of cells the plane allows (at most ~3 per column).
// Measured on lavapipe (110K triangles, 32^3): spreading one triangle's columns over 4
// invocations cost ~2x the CPU time (each repeats the triangle's loads and setup), one flat
// loop over the whole box was no faster (more candidates). With parts switched off, the
// candidates' distances were ~1/2 of the kernel, the atomics ~1/4, the crossings ~1/6.
void scatterDistance(vec3 a, vec3 b, vec3 c, ivec3 dims) {
  float reach = enumerationReach(a, b, c);
  vec3 lo = min(min(a, b), c) - reach;
  vec3 hi = max(max(a, b), c) + reach;
  // Cells whose centre k + 0.5 lies in [lo, hi], clamped in float before converting.
  ivec3 kLo = ivec3(clamp(ceil(lo - 0.5), vec3(0.0), vec3(dims)));
  ivec3 kHi = ivec3(clamp(floor(hi - 0.5), vec3(-1.0), vec3(dims - 1)));
  if (any(greaterThan(kLo, kHi))) return;
  VoxTriangle triangle;
  vox_setupTriangle(a, b, c, triangle);
  vec3 n = vox_cross(b - a, c - a);
  vec3 an = abs(n);
  int w = an.z >= an.x && an.z >= an.y ? 2 : (an.y >= an.x ? 1 : 0);
  vec3 nUVW = toUVW(n, w);
  vec3 aUVW = toUVW(a, w);
  ivec3 loUVW = toUVW(kLo, w);
  ivec3 hiUVW = toUVW(kHi, w);
  float len = length(n);
  bool slab = nUVW.z != 0.0 && !isinf(len) && len > 0.0;
  float halfWidth = slab ? reach * (len / abs(nUVW.z)) : 0.0;
  float inverseNW = slab ? 1.0 / nUVW.z : 0.0;
  for (int iu = loUVW.x; iu <= hiUVW.x; ++iu) {
    for (int iv = loUVW.y; iv <= hiUVW.y; ++iv) {
      int wLo = loUVW.z;
      int wHi = hiUVW.z;
      if (slab) {
        float cu = float(iu) + 0.5;
        float cv = float(iv) + 0.5;
        float w0 = aUVW.z - (nUVW.x * (cu - aUVW.x) + nUVW.y * (cv - aUVW.y)) * inverseNW;
        wLo = max(wLo, int(clamp(ceil(w0 - halfWidth - 0.5), -1.0, float(hiUVW.z + 1))));
        wHi = min(wHi, int(clamp(floor(w0 + halfWidth - 0.5), -1.0, float(hiUVW.z + 1))));
      }
      for (int iw = wLo; iw <= wHi; ++iw) {
        ivec3 cell = fromUVW(ivec3(iu, iv, iw), w);
        vec3 p = vec3(cell) + 0.5;
        float dist;
        vec3 dir;
        vox_pointTriangle(p, triangle, dist, dir);
        if (!(dist < SSLPV_VOX_WHOLE_CELL)) continue;
        uint index = (uint(cell.z) * uint(dims.y) + uint(cell.y)) * uint(dims.x) + uint(cell.x);
        uint packed = vox_pack(dist, dir);
        // Values only decrease: a plain read that is already lower saves the atomic.
        if (packed < nearest[index]) atomicMin(nearest[index], packed);
      }
    }
  }
}

// Twin of edgeSign() in volume/lpv/voxelize_parity.cpp: the sign of the edge function of
// p->q at column c, exact through 64-bit products (imulExtended), evaluated in one
// canonical direction of the edge, ties broken as if c moved by (eps, eps^2).
int edgeSign(ivec2 p, ivec2 q, ivec2 c) {
  bool swapped = p.x > q.x || (p.x == q.x && p.y > q.y);
  ivec2 s = swapped ? q : p;
  ivec2 e = swapped ? p : q;
  if (s == e) return 0;
  int hi1, lo1, hi2, lo2;
  imulExtended(e.x - s.x, c.y - s.y, hi1, lo1);
  imulExtended(e.y - s.y, c.x - s.x, hi2, lo2);
  int sign;
  if (hi1 != hi2) {
    sign = hi1 > hi2 ? 1 : -1;
  } else if (lo1 != lo2) {
    sign = uint(lo1) > uint(lo2) ? 1 : -1;
  } else {
    sign = s.y != e.y ? (s.y > e.y ? 1 : -1) : 1;
  }
  return swapped ? -sign : sign;
}

void scatterParity(vec3 a, vec3 b, vec3 c, ivec3 dims) {
  if (floor(min(min(a.z, b.z), c.z) + 0.5) >= float(dims.z)) return;
  // Columns whose centre x + 0.5 may lie in the projection's box: a float bound with a
  // margin far above the fixed-point rounding; the exact edge test decides. Most triangles
  // of a fine mesh cover no column, and lavapipe skips a loop no lane enters (an `if`
  // runs under a mask whatever it holds), so the fixed-point work sits inside the loop.
  vec2 lo = clamp(ceil(min(min(a.xy, b.xy), c.xy) - 0.5 - 1e-3), vec2(0.0), vec2(dims.xy));
  vec2 hi = clamp(floor(max(max(a.xy, b.xy), c.xy) - 0.5 + 1e-3), vec2(-1.0), vec2(dims.xy - 1));
  for (int y = int(lo.y); y <= int(hi.y); ++y) {
    for (int x = int(lo.x); x <= int(hi.x); ++x) {
      ivec2 pa = ivec2(vox_fixed(a.x), vox_fixed(a.y));
      ivec2 pb = ivec2(vox_fixed(b.x), vox_fixed(b.y));
      ivec2 pc = ivec2(vox_fixed(c.x), vox_fixed(c.y));
      ivec2 column = ivec2(x, y) * 4096;
      int s0 = edgeSign(pa, pb, column);
      int s1 = edgeSign(pb, pc, column);
      int s2 = edgeSign(pc, pa, column);
      if (s0 == 0 || s0 != s1 || s1 != s2) continue;
      int z = max(0, vox_crossingCell(a, b, c, float(x) + 0.5, float(y) + 0.5));
      if (z >= dims.z) continue;
      uint word = (uint(y) * uint(dims.x) + uint(x)) * uint(push.wordsPerColumn) + uint(z >> 5);
      atomicXor(parity[word], 1u << uint(z & 31));
    }
  }
}

void main() {
  ivec3 dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  vec3 origin = vec3(push.originX, push.originY, push.originZ);
  uint lastVertex = uint(positions.length()) - 1u;
  for (uint t = gl_GlobalInvocationID.x; t < push.triangleCount; t += push.threadCount) {
    // Indices are validated on upload; the clamp only keeps a bad buffer in bounds.
    vec3 a = vox_toGrid(positions[min(indices[3u * t], lastVertex)].xyz, origin, push.inverseCellSize);
    vec3 b = vox_toGrid(positions[min(indices[3u * t + 1u], lastVertex)].xyz, origin, push.inverseCellSize);
    vec3 c = vox_toGrid(positions[min(indices[3u * t + 2u], lastVertex)].xyz, origin, push.inverseCellSize);
    scatterDistance(a, b, c, dims);
    scatterParity(a, b, c, dims);
  }
}

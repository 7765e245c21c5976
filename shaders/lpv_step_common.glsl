// Interface and shared pieces of the LPV step kernels (lpv_propagate.comp,
// lpv_accumulate.comp). A kernel that sums per workgroup declares `shared vec4 <name>[]`
// with an entry per invocation and defines SSLPV_GROUP_SCRATCH as <name> before
// including this.
// Cells are 3 vec4 (one per channel: c0, c1x, c1y, c1z), x fastest.
#ifndef SSLPV_LPV_STEP_COMMON_GLSL
#define SSLPV_LPV_STEP_COMMON_GLSL

#include "volume/lpv_constants.h"
#include "shaders/lpv_shared.h"
#include "shaders/lpv_transfer.glsl"

layout(push_constant) uniform PushBlock { SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;

layout(std430, binding = 0) readonly buffer SourceField { vec4 source[]; };
layout(std430, binding = 1) writeonly buffer DestinationField { vec4 destination[]; };
layout(std430, binding = 2) buffer AccumulatedField { vec4 accumulated[]; };
// Per cell: (dc.rgb, active), (linear.rgb, 0).
layout(std430, binding = 3) readonly buffer StepFactors { vec4 factors[]; };
layout(std430, binding = 4) writeonly buffer PartialSums { vec4 partials[]; };
layout(std430, binding = 5) readonly buffer Control { SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD) } control;

ivec3 dims;

struct Source {
  vec4 c[3];
};

/// Power sums of one invocation, in the SSLPV_ENERGY_* layout.
struct StepSums {
  vec3 emitted, clampRemoved, gathered, absorbed, kept;
};

StepSums noSums() { return StepSums(vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0)); }

bool inGrid(ivec3 cell) { return all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, dims)); }
bool interior(ivec3 cell) { return all(greaterThanEqual(cell, ivec3(1))) && all(lessThan(cell, dims - 1)); }
uint cellIndex(ivec3 cell) { return uint((cell.z * dims.y + cell.y) * dims.x + cell.x); }

/// Loads a source cell as stored (the previous step's light); zero outside the grid.
/// `dc` receives the cell's (dc.rgb, active).
Source loadRaw(ivec3 cell, out vec4 dc) {
  Source s;
  if (!inGrid(cell)) {
    s.c[0] = s.c[1] = s.c[2] = vec4(0.0);
    dc = vec4(0.0);
    return s;
  }
  const uint i = cellIndex(cell);
  s.c[0] = source[3 * i];
  s.c[1] = source[3 * i + 1];
  s.c[2] = source[3 * i + 2];
  dc = factors[2 * i];
  return s;
}

/// The light a source sends: normalized when active (normalizeEmission on the CPU). Adds
/// its power to `sums` when `count` (each cell is counted by exactly one invocation).
Source emission(Source raw, vec4 dc, bool count, inout StepSums sums) {
  if (dc.w == 0.0) return raw;
  Source s;
  vec3 emitted = vec3(0.0), clampRemoved = vec3(0.0);
  s.c[0] = normalizeEmission(raw.c[0], emitted.x, clampRemoved.x);
  s.c[1] = normalizeEmission(raw.c[1], emitted.y, clampRemoved.y);
  s.c[2] = normalizeEmission(raw.c[2], emitted.z, clampRemoved.z);
  if (count) {
    sums.emitted += emitted;
    sums.clampRemoved += clampRemoved;
  }
  return s;
}

/// A halo source: the emission of a cell another invocation owns (and counts).
Source loadHaloEmission(ivec3 cell) {
  StepSums unused = noSums();
  vec4 dc;
  return emission(loadRaw(cell, dc), dc, false, unused);
}

/// Gathers one channel into a destination from its 6 neighbours, in the CPU's order:
/// per axis, light travelling -e_a (from the +e_a neighbour), then +e_a.
vec4 gatherChannel(vec4 fromPlusX, vec4 fromMinusX, vec4 fromPlusY, vec4 fromMinusY, vec4 fromPlusZ,
                   vec4 fromMinusZ) {
  vec4 g = transferX(fromPlusX, -1.0);
  g += transferX(fromMinusX, 1.0);
  g += transferY(fromPlusY, -1.0);
  g += transferY(fromMinusY, 1.0);
  g += transferZ(fromPlusZ, -1.0);
  g += transferZ(fromMinusZ, 1.0);
  return g;
}

/// Applies the step factors to the gathered light of an active interior cell (one vec4
/// per channel), writes the result and adds it to the power sums. Every other step
/// (push.accumulate) adds both the cell's source (the previous step's result) and the
/// new result to the accumulated light, which halves the traffic on that buffer.
void storeCell(uint cell, vec4 dc, vec4 gathered[3], Source raw, inout StepSums sums) {
  const vec4 linear = factors[2 * cell + 1];
  for (int ch = 0; ch < 3; ++ch) {
    const vec4 value = gathered[ch] * vec4(dc[ch], linear[ch], linear[ch], linear[ch]);
    destination[3 * cell + ch] = value;
    if (push.accumulate != 0) accumulated[3 * cell + ch] += raw.c[ch] + value;
    sums.gathered[ch] += gathered[ch].x;
    sums.absorbed[ch] += gathered[ch].x * (1.0 - dc[ch]);
    sums.kept[ch] += value.x;
  }
}

/// Inactive interior cells hold no light after a step.
void storeInactive(uint cell) {
  destination[3 * cell] = destination[3 * cell + 1] = destination[3 * cell + 2] = vec4(0.0);
}

#ifdef SSLPV_GROUP_SCRATCH
/// Sums one vec4 over the workgroup through the scratch array (which must be free);
/// the result is valid in invocation 0.
vec4 groupSum(vec4 value) {
  const uint li = gl_LocalInvocationIndex;
  const uint size = gl_WorkGroupSize.x * gl_WorkGroupSize.y * gl_WorkGroupSize.z;
  SSLPV_GROUP_SCRATCH[li] = value;
  barrier();
  uint width = 1;
  while (width < size) width <<= 1;
  for (uint s = width >> 1; s > 0; s >>= 1) {
    if (li < s && li + s < size) SSLPV_GROUP_SCRATCH[li] += SSLPV_GROUP_SCRATCH[li + s];
    barrier();
  }
  const vec4 total = SSLPV_GROUP_SCRATCH[0];
  barrier();
  return total;
}

/// Writes this workgroup's row of partial power sums (all invocations must call it).
void storePartials(StepSums sums) {
  const uint group =
      (gl_WorkGroupID.z * gl_NumWorkGroups.y + gl_WorkGroupID.y) * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const vec4 row[4] = vec4[4](vec4(sums.emitted, sums.clampRemoved.x), vec4(sums.clampRemoved.yz, sums.gathered.xy),
                              vec4(sums.gathered.z, sums.absorbed), vec4(sums.kept, 0.0));
  for (int k = 0; k < 4; ++k) {
    const vec4 total = groupSum(row[k]);
    if (gl_LocalInvocationIndex == 0) partials[4 * group + k] = total;
  }
}
#endif

#endif

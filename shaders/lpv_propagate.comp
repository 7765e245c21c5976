#version 460
// One LPV propagation step (normalize + transfer + factors + accumulate, fused), the GPU
// twin of volume/cpu/propagate.cpp, run only over the occupied part of the grid.
//
// A workgroup is one work item: a tile of SSLPV_TILE_X x ROWS cells in x, y marching
// through a run of slices [zBegin, zEnd) in which the tile holds active cells (the host
// lists them from StepFactors::active; cells outside every item hold no light and are
// never read or written, except as zero halos). One invocation owns one x column of the
// tile. Each source cell is fetched and normalized once per item, and sends its 6 lobes
// (lpv_transfer.glsl) straight into register accumulators of the cells receiving them:
// the rows above and below in the same lane, the x neighbours through subgroup shuffles,
// the slices before and after in the accumulators of 3 slices kept in flight. Only the
// halo is fetched twice: one row either side, the two x columns packed TILE_X / 2 rows per
// vector, one slice either end of the run.
//
// Why not shared memory: on lavapipe a shared-memory access costs as much as a buffer
// access (both are loops over the SIMD lanes) while a shuffle is a register permute, and
// an `if` never skips work (both sides run under a mask) while a loop whose lanes are
// all inactive does exit: the auto-steps stop is therefore a loop. Nested loops cost
// (llvmpipe masks every write inside them), so accumulation is a pipeline variant rather
// than a loop, and the march loads its first two slices in a prologue.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_shuffle_relative : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_control_flow_attributes : require

#include "shaders/lpv_step_common.glsl"
#include "shaders/lpv_transfer.glsl"

layout(local_size_x = SSLPV_TILE_X) in;
// ROWS (lpv_step_common.glsl): registers per invocation grow with it.
/// 1: this step accumulates (push.accumulate one of the SSLPV_ACCUMULATE_* other than
/// NONE; the START modes overwrite, so the first step of a device-resident run needs no
/// cleared buffer). 0: it does not.
layout(constant_id = 1) const int ACCUMULATE = 0;
/// 1: the source field has no linear band and the step factors keep it so (the calibrated
/// scheme after its first step): emitIsotropicChannel instead of the clamped faces.
layout(constant_id = 2) const int ISOTROPIC = 0;
/// 1 (with ISOTROPIC 1, ACCUMULATE 0): a Chebyshev iterate x_{k+1} = ω (T x_k + y - x_{k-1})
/// + x_{k-1} of a device-resident auto run (chebyshevSlice on the CPU): the source field
/// is x_k, the destination holds x_{k-1} and receives x_{k+1} (each cell reads its own
/// value before writing it), the accumulated light holds y, the first step's light, and
/// ω comes from the control record (lpv_reduce.comp); a probe step is the same with
/// ω = 1 and no y. The sums carry Σ |x_{k+1} - x_k| as gathered and Σ x_{k+1} as kept.
layout(constant_id = 3) const int CHEBYSHEV = 0;

const int W = SSLPV_TILE_X;
const int HALF = SSLPV_TILE_X / 2;
const int HALO_VECTORS = (ROWS + HALF - 1) / HALF;

/// Power sums of one invocation, in the SSLPV_ENERGY_* layout.
struct StepSums {
  vec3 emitted, clampRemoved, gathered, absorbed, kept, source;
};

/// Light arriving in one cell, per channel.
struct Gathered {
  vec4 c[3];
};

/// The lobes of one source cell, per channel. Every cell is normalized, active or not:
/// cells outside the medium hold no light, and zero light sends nothing. `owned` (0 or 1)
/// counts the cell's power in `sums`, so that each cell is counted by one invocation.
struct CellLobes {
  Lobes ch[3];
};

/// Each face passes conductance[i] · conductance[j]: the sender's factor is applied here,
/// the receiver's in storeCell, as on the CPU (gatherSlice).
vec3 fetchConductance(int x, int y, int z) {
  const bool valid = inGrid(x, y, z);
  const int i = cellIndex(valid ? x : 0, valid ? y : 0, valid ? z : 0);
  return texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 4).xyz;
}

/// The lobes of source cell (x, y, z).
CellLobes emitCell(int x, int y, int z, float owned, inout StepSums sums) {
  const Cell raw = fetchSource(x, y, z);
  const vec3 conductance = fetchConductance(x, y, z);
  CellLobes lobes;
  vec3 emitted = vec3(0.0), clampRemoved = vec3(0.0);
  for (int ch = 0; ch < 3; ++ch) {
    if (ISOTROPIC != 0)
      lobes.ch[ch] = emitIsotropicChannel(raw.c[ch], conductance[ch], CHEBYSHEV != 0, emitted[ch]);
    else
      lobes.ch[ch] = emitChannel(raw.c[ch], conductance[ch], emitted[ch], clampRemoved[ch]);
  }
  sums.emitted += owned * emitted;
  sums.clampRemoved += owned * clampRemoved;
  sums.source += owned * vec3(raw.c[0].x, raw.c[1].x, raw.c[2].x);
  return lobes;
}

/// Halo vector h: lane l < HALF holds the cell left of the tile in row h * HALF + l, lane
/// l >= HALF the cell right of it in row h * HALF + l - HALF. Returns its (x, y).
ivec2 haloCell(ivec2 origin, int lane, int h) {
  const int row = h * HALF + lane % HALF;
  const int x = lane < HALF ? origin.x - 1 : origin.x + W;
  return ivec2(x, row < ROWS ? origin.y + row : -1);  // rows past the tile: outside, zero
}

/// Applies the step factors to the light gathered into cell (x, y, z), writes it, and
/// every other step adds it to the accumulated light together with the cell's source as
/// stored (the previous step's light; fetched again, which measured faster than keeping
/// it in registers), so that accumulating every other step covers every step. Inactive
/// cells get 0.
void storeCell(int x, int y, int z, Gathered gathered, inout StepSums sums) {
  if (!interiorXY(x, y)) return;  // also outside the grid; the ring never holds light
  const int i = cellIndex(x, y, z);
  const vec4 dc = texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i);
  const vec4 linear = texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 1);
  const vec3 conductance = texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 4).xyz;
  const float on = dc.w;
  vec4 value[3];
  if (CHEBYSHEV != 0) {
    // Probe steps are plain linear steps: weight 1, no source.
    const bool probe = push.chebyshev == SSLPV_CHEBYSHEV_PROBE;
    const vec3 omega = probe ? vec3(1.0) : vec3(control.omegaR, control.omegaG, control.omegaB);
    for (int ch = 0; ch < 3; ++ch) {
      const float older = texelFetch(otherField, 3 * i + ch).x;
      const float current = texelFetch(sourceField, 3 * i + ch).x;
      const float y = probe ? 0.0 : texelFetch(accumulatedIn, 3 * i + ch).x;
      const float next = on * (omega[ch] * (conductance[ch] * gathered.c[ch].x * dc[ch] + y - older) + older);
      destination[3 * i + ch] = vec4(next, 0.0, 0.0, 0.0);
      sums.gathered[ch] += abs(next - current);
      sums.kept[ch] += next;
    }
    return;
  }
  for (int ch = 0; ch < 3; ++ch) {
    // A negative retention drains at most what the cell gathered (gatherSlice on the CPU).
    gathered.c[ch] *= conductance[ch] * (gathered.c[ch].x > 0.0 ? 1.0 : 0.0);
    value[ch] = on * gathered.c[ch] * vec4(dc[ch], linear[ch], linear[ch], linear[ch]);
    destination[3 * i + ch] = value[ch];
    sums.gathered[ch] += on * gathered.c[ch].x;
    sums.absorbed[ch] += on * gathered.c[ch].x * (1.0 - dc[ch]);
    sums.kept[ch] += value[ch].x;
  }
  if (ACCUMULATE != 0) {
    // Overwriting multiplies the old value by 0: the buffer is cleared once at setup, so
    // it never holds a NaN.
    const float keep = push.accumulate == SSLPV_ACCUMULATE_ADD ? 1.0 : 0.0;
    // Step 0 of a device-resident run: its source is the injected light, which enters the
    // accumulated light times the fresh gain (addInjected on the CPU). Before Chebyshev
    // iterates the accumulated light holds this step's alone, their y; the finish adds
    // the injected light.
    const vec3 sourceGain = push.accumulate == SSLPV_ACCUMULATE_START_FRESH
                                ? texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 3).xyz
                            : push.accumulate == SSLPV_ACCUMULATE_START_RESULT ? vec3(0.0)
                                                                               : vec3(1.0);
    for (int ch = 0; ch < 3; ++ch)
      accumulated[3 * i + ch] =
          keep * texelFetch(accumulatedIn, 3 * i + ch) + sourceGain[ch] * texelFetch(sourceField, 3 * i + ch) + value[ch];
  }
}

/// ρ times the outside neighbours of cell (x, y, z), per channel; zero outside the grid
/// (branch-free like fetchSource).
vec3 fetchRetention(int x, int y, int z) {
  const bool valid = inGrid(x, y, z);
  const int i = cellIndex(valid ? x : 0, valid ? y : 0, valid ? z : 0);
  return valid ? texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 2).xyz : vec3(0.0);
}

Gathered nothing() { return Gathered(vec4[3](vec4(0.0), vec4(0.0), vec4(0.0))); }

void main() {
  dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  const uvec4 item = items[gl_WorkGroupID.x];
  const ivec2 origin = ivec2(item.xy);
  const int z0 = int(item.z), z1 = int(item.w);
  const int lane = int(gl_SubgroupInvocationID);
  const int x = origin.x + lane;
  StepSums sums = StepSums(vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));

  // Runs once unless auto steps stopped in an earlier step of current submission.
  for (int stopped = control.stopped; stopped == 0; stopped = 1) {
    // Light gathered so far into the tile's rows of slices z (current), z + 1 and z + 2.
    Gathered current[ROWS], next[ROWS], later[ROWS];
    [[unroll]] for (int r = 0; r < ROWS; ++r) current[r] = next[r] = later[r] = nothing();
    // Slice z0 - 1 only matters for the light it sends up into slice z0.
    [[unroll]] for (int r = 0; r < ROWS; ++r) {
      const CellLobes lobes = emitCell(x, origin.y + r, z0 - 1, 0.0, sums);
      for (int ch = 0; ch < 3; ++ch) next[r].c[ch] += lobes.ch[ch].toward[PLUS_Z];
    }
    // Iteration z loads slice s = z + 1, whose light goes down into z, sideways within s
    // and up into s + 1; slice z is then complete. The first iteration completes nothing
    // (slice z0 - 1 is not the item's), which costs less than a second copy of the loop
    // body as a prologue would in compile time.
    for (int z = z0 - 1; z < z1; ++z) {
      const int s = z + 1;
      const float owns = s < z1 && x < dims.x ? 1.0 : 0.0;
      // The halo rows send light into the tile's first and last rows.
      const CellLobes haloBelow = emitCell(x, origin.y - 1, s, 0.0, sums);
      const CellLobes haloAbove = emitCell(x, origin.y + ROWS, s, 0.0, sums);
      for (int ch = 0; ch < 3; ++ch) {
        next[0].c[ch] += haloBelow.ch[ch].toward[PLUS_Y];
        next[ROWS - 1].c[ch] += haloAbove.ch[ch].toward[MINUS_Y];
      }
      // The x halo columns send light into the tile's first and last lanes.
      [[unroll]] for (int h = 0; h < HALO_VECTORS; ++h) {
        const ivec2 haloXY = haloCell(origin, lane, h);
        const CellLobes halo = emitCell(haloXY.x, haloXY.y, s, 0.0, sums);
        for (int ch = 0; ch < 3; ++ch) {
          const vec4 inward = lane < HALF ? halo.ch[ch].toward[PLUS_X] : halo.ch[ch].toward[MINUS_X];
          [[unroll]] for (int k = 0; k < HALF; ++k) {
            const int r = h * HALF + k;
            // Every lane shuffles (a shuffle from an inactive lane is undefined), then picks.
            const vec4 fromLeft = subgroupShuffle(inward, uint(k));
            const vec4 fromRight = subgroupShuffle(inward, uint(HALF + k));
            if (r < ROWS) next[r].c[ch] += lane == 0 ? fromLeft : lane == W - 1 ? fromRight : vec4(0.0);
          }
        }
      }
      [[unroll]] for (int r = 0; r < ROWS; ++r) {
        const CellLobes lobes = emitCell(x, origin.y + r, s, r < ROWS ? owns : 0.0, sums);
        // The boundary returns ρ per outside neighbour of what the cell sends one
        // neighbour (its cells are isotropic in the calibrated scheme; 0 in the seed's);
        // with a varying D, all the cell keeps, per conductance² (the lobes carry one
        // factor, storeCell the other).
        const vec3 retention = fetchRetention(x, origin.y + r, s);
        for (int ch = 0; ch < 3; ++ch) {
          next[r].c[ch].x += retention[ch] * lobes.ch[ch].toward[PLUS_X].x;
          const vec4 fromLeftLane = subgroupShuffleUp(lobes.ch[ch].toward[PLUS_X], 1);
          const vec4 fromRightLane = subgroupShuffleDown(lobes.ch[ch].toward[MINUS_X], 1);
          next[r].c[ch] += (lane > 0 ? fromLeftLane : vec4(0.0)) + (lane < W - 1 ? fromRightLane : vec4(0.0));
          if (r + 1 < ROWS) next[r + 1].c[ch] += lobes.ch[ch].toward[PLUS_Y];
          if (r > 0) next[r - 1].c[ch] += lobes.ch[ch].toward[MINUS_Y];
          current[r].c[ch] += lobes.ch[ch].toward[MINUS_Z];
          later[r].c[ch] += lobes.ch[ch].toward[PLUS_Z];
        }
      }
      if (z >= z0)
        [[unroll]] for (int r = 0; r < ROWS; ++r) storeCell(x, origin.y + r, z, current[r], sums);
      [[unroll]] for (int r = 0; r < ROWS; ++r) {
        current[r] = next[r];
        next[r] = later[r];
        later[r] = nothing();
      }
    }

    const vec4 row[SSLPV_ENERGY_VEC4S] = vec4[SSLPV_ENERGY_VEC4S](
        vec4(sums.emitted, sums.clampRemoved.x), vec4(sums.clampRemoved.yz, sums.gathered.xy),
        vec4(sums.gathered.z, sums.absorbed), vec4(sums.kept, sums.source.x), vec4(sums.source.yz, 0.0, 0.0));
    for (int k = 0; k < SSLPV_ENERGY_VEC4S; ++k) {
      const vec4 total = subgroupAdd(row[k]);
      if (subgroupElect()) partials[SSLPV_ENERGY_VEC4S * gl_WorkGroupID.x + k] = total;
    }
  }
}

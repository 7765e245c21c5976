#version 460
// One LPV propagation step (normalize + gather + factors + accumulate, fused), the GPU
// twin of volume/propagate.cpp. A workgroup owns a TX x TY column of cells and marches
// it through a chunk of z. Each source cell is loaded and normalized once per column;
// its x/y neighbours read it from a shared-memory slice with a 1-cell halo, its z
// neighbours from registers. On lavapipe every buffer or shared access is a loop over
// the SIMD lanes and both sides of every branch run, so the kernel keeps accesses few
// and wide (vec4) rather than skipping work with branches.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x_id = 0, local_size_y_id = 1, local_size_z = 1) in;

const uint TX = gl_WorkGroupSize.x;
const uint TY = gl_WorkGroupSize.y;
const uint HX = TX + 2;  // slice width with the halo

// One z slice of sources with a 1-cell halo; also the scratch of the final reduction
// (it has more than TX*TY entries), so that is all the shared memory: 19 KiB at 64x4.
shared vec4 slice[(TX + 2) * (TY + 2) * 3];
#define SSLPV_GROUP_SCRATCH slice
#include "shaders/lpv_step_common.glsl"

/// `local` is in tile coordinates: -1 and TX / TY address the halo.
void storeSlice(ivec2 local, Source s) {
  const uint base = 3 * (uint(local.y + 1) * HX + uint(local.x + 1));
  slice[base] = s.c[0];
  slice[base + 1] = s.c[1];
  slice[base + 2] = s.c[2];
}

vec4 sliceAt(ivec2 local, int ch) { return slice[3 * (uint(local.y + 1) * HX + uint(local.x + 1)) + ch]; }

void main() {
  // Auto steps stopped in an earlier step of this batch: leave the buffers alone.
  if (control.stopped != 0) return;
  dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  const ivec2 local = ivec2(gl_LocalInvocationID.xy);
  const ivec2 groupOrigin = ivec2(gl_WorkGroupID.xy * uvec2(TX, TY));
  const ivec2 own = groupOrigin + local;
  const int z0 = int(gl_WorkGroupID.z) * push.zChunk;
  const int z1 = min(z0 + push.zChunk, dims.z);

  // The first 2*(TX+TY) invocations each load one halo cell of every slice (no corners:
  // the gather has no diagonal neighbours).
  const uint li = gl_LocalInvocationIndex;
  const bool loadsHalo = li < 2 * (TX + TY);
  ivec2 halo;  // tile coordinates of this invocation's halo cell
  if (li < TX) halo = ivec2(li, -1);
  else if (li < 2 * TX) halo = ivec2(li - TX, TY);
  else if (li < 2 * TX + TY) halo = ivec2(-1, li - 2 * TX);
  else halo = ivec2(TX, li - 2 * TX - TY);

  StepSums sums = noSums();
  vec4 ownDc, nextDc;
  Source below = loadHaloEmission(ivec3(own, z0 - 1));
  Source centerRaw = loadRaw(ivec3(own, z0), ownDc);
  Source center = emission(centerRaw, ownDc, true, sums);
  storeSlice(local, center);
  if (loadsHalo) storeSlice(halo, loadHaloEmission(ivec3(groupOrigin + halo, z0)));
  barrier();

  for (int z = z0; z < z1; ++z) {
    const Source aboveRaw = loadRaw(ivec3(own, z + 1), nextDc);
    const Source above = emission(aboveRaw, nextDc, z + 1 < z1, sums);
    const ivec3 cell = ivec3(own, z);
    if (interior(cell)) {
      const uint index = cellIndex(cell);
      if (ownDc.w != 0.0) {
        vec4 gathered[3];
        for (int ch = 0; ch < 3; ++ch)
          gathered[ch] = gatherChannel(sliceAt(local + ivec2(1, 0), ch), sliceAt(local - ivec2(1, 0), ch),
                                       sliceAt(local + ivec2(0, 1), ch), sliceAt(local - ivec2(0, 1), ch),
                                       above.c[ch], below.c[ch]);
        storeCell(index, ownDc, gathered, centerRaw, sums);
      } else {
        storeInactive(index);
      }
    }
    barrier();  // everyone is done reading slice z
    storeSlice(local, above);
    if (loadsHalo) storeSlice(halo, loadHaloEmission(ivec3(groupOrigin + halo, z + 1)));
    barrier();
    below = center;
    center = above;
    centerRaw = aboveRaw;
    ownDc = nextDc;
  }
  storePartials(sums);
}

#version 460
// Injection: the twin of sslpv::injectSamples (volume/cpu/inject.cpp). Each GpuFluxSample
// that hit the object adds, in the seed scheme, a clamped cosine lobe holding flux/π about
// its refracted direction, half a cell inside the surface (a full cell deeper when no
// active cell is near), spread over active cells with activeTrilinearWeights; in the
// calibrated scheme (push.calibrated) per channel an isotropic source of the same power at
// max(depth cos θt, Δx / 2) along the inward normal, its power times the oblique-entry
// gain (sslpv::obliqueEntryGain), the depth and the gain's nodes read from the surface
// cell's record in binding 4 and θt the refracted direction's angle to the normal. Neighbouring samples
// write the same cells, so the lobes are added with float atomics. Each workgroup also
// sums the injected and dropped flux of its samples into one row of partial sums, which
// the host adds in double.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require

#include "device_shared/lpv_constants.h"
#include "device_shared/flux_sample_shared.h"
#include "device_shared/cell_coverage_shared.h"

layout(local_size_x = SSLPV_INJECT_GROUP) in;

layout(push_constant) uniform PushBlock { SSLPV_INJECT_PUSH_FIELDS(SSLPV_CC_DECLARE_FIELD) } push;

layout(std430, binding = 0) readonly buffer Samples { GpuFluxSample samples[]; };
#define SSLPV_CELL_COVERAGE_BINDING 1
#include "shaders/cell_coverage.glsl"
// The light field in GpuPropagator's layout: per cell 3 vec4 (one per channel: c0, c1x,
// c1y, c1z), as 12 floats so that each coefficient can be added atomically.
layout(std430, binding = 2) buffer Field { float field[]; };
layout(std430, binding = 3) writeonly buffer Stats { vec4 partials[]; };
// Per cell, x-fastest, SSLPV_CALIBRATED_INJECTION_VEC4 vec4: (injection depth rgb, ior²),
// the oblique-entry gain nodes of r, g and b and the entry coupling rgb
// (cell_coverage_shared.h); unread in the seed scheme.
layout(std430, binding = 4) readonly buffer Calibration { vec4 calibration[]; };

// sslpv::obliqueEntryGain: piecewise linear in y = cos² θi over nodes at
// y = 1 - k / SSLPV_OBLIQUE_INTERVALS, k = 1..4, and 1 at y = 1.
float obliqueEntryGain(vec4 nodes, float y) {
  const float x = clamp((1.0 - y) * float(SSLPV_OBLIQUE_INTERVALS), 0.0, float(SSLPV_OBLIQUE_INTERVALS));
  const int k = min(int(x), SSLPV_OBLIQUE_INTERVALS - 1);
  const float below = k == 0 ? 1.0 : nodes[k - 1], above = nodes[k];
  return below + (x - float(k)) * (above - below);
}

shared vec4 injectedSums[SSLPV_INJECT_GROUP];
shared vec4 droppedSums[SSLPV_INJECT_GROUP];

void main() {
  const CellGrid grid = SSLPV_CELL_GRID_FROM(push);
  const float halfCell = 0.5 * grid.cellSize;
  vec3 injected = vec3(0.0), dropped = vec3(0.0);
  // A bounded number of workgroups strides over the samples, so the partial-sum rows
  // (one per workgroup) have a fixed size whatever the sample count.
  const uint stride = gl_NumWorkGroups.x * SSLPV_INJECT_GROUP;
  for (uint s = gl_GlobalInvocationID.x; s < push.sampleCount; s += stride) {
    const GpuFluxSample rec = samples[s];
    if (rec.positionValid.w == 0.0) continue;  // the texel's ray missed the object
    const vec3 p = rec.positionValid.xyz, n = rec.normal.xyz;
    uint cells[8];
    float weights[8];
    int used = activeTrilinearWeights(grid, p - halfCell * n, cells, weights);
    // Thin features: look a full cell deeper before giving up on the sample.
    if (used == 0) used = activeTrilinearWeights(grid, p - grid.cellSize * n, cells, weights);
    if (used == 0) {
      dropped += rec.flux.rgb;
      continue;
    }
    if (push.calibrated == 0u) {
      for (int ch = 0; ch < 3; ++ch) {
        // A Lambertian emitter of power Φ has intensity (Φ/π) max(0, cos).
        const vec4 lobe = vec4(float(SSLPV_COSINE_LOBE_C0), float(SSLPV_COSINE_LOBE_C1) * rec.direction.xyz) *
                          (rec.flux[ch] / float(SSLPV_PI));
        for (int i = 0; i < used; ++i) {
          const uint base = 12u * cells[i] + 4u * uint(ch);
          for (int k = 0; k < 4; ++k) atomicAdd(field[base + uint(k)], weights[i] * lobe[k]);
        }
      }
    } else {
      // The surface cell: the largest weight, the first of equals (as depthCell).
      int surface = 0;
      for (int i = 1; i < used; ++i)
        if (weights[i] > weights[surface]) surface = i;
      // The refracted beam first scatters about the depth along its path (inject.cpp).
      const float cosRefracted = max(0.0, -dot(rec.direction.xyz, n));
      const uint record = SSLPV_CALIBRATED_INJECTION_VEC4 * cells[surface];
      const vec4 depthAndIor = calibration[record];
      const vec3 depths = max(vec3(halfCell), depthAndIor.xyz * cosRefracted);
      // incidentCosineSquared: cos² θi outside from cos θt inside.
      const float incidence = clamp(1.0 - depthAndIor.w * (1.0 - cosRefracted * cosRefracted), 0.0, 1.0);
      for (int ch = 0; ch < 3; ++ch) {
        uint deepCells[8];
        float deepWeights[8];
        int deepUsed = activeTrilinearWeights(grid, p - depths[ch] * n, deepCells, deepWeights);
        if (deepUsed == 0)
          deepUsed = activeTrilinearWeights(grid, p - (depths[ch] + halfCell) * n, deepCells, deepWeights);
        // Deeper than the object is thick: keep the light where it entered.
        if (deepUsed == 0) {
          deepUsed = used;
          deepCells = cells;
          deepWeights = weights;
        }
        // Isotropic with power Φ: the c0 of a cosine lobe of power Φ, no linear band.
        const float gain = obliqueEntryGain(calibration[record + 1u + uint(ch)], incidence) * calibration[record + 4u][ch];
        const float c0 = float(SSLPV_COSINE_LOBE_C0) * gain * rec.flux[ch] / float(SSLPV_PI);
        for (int i = 0; i < deepUsed; ++i) atomicAdd(field[12u * deepCells[i] + 4u * uint(ch)], deepWeights[i] * c0);
      }
    }
    injected += rec.flux.rgb;
  }

  const uint li = gl_LocalInvocationIndex;
  injectedSums[li] = vec4(injected, 0.0);
  droppedSums[li] = vec4(dropped, 0.0);
  barrier();
  for (uint half_ = SSLPV_INJECT_GROUP / 2; half_ > 0; half_ >>= 1) {
    if (li < half_) {
      injectedSums[li] += injectedSums[li + half_];
      droppedSums[li] += droppedSums[li + half_];
    }
    barrier();
  }
  if (li == 0) {
    partials[SSLPV_INJECT_STATS_VEC4 * gl_WorkGroupID.x] = injectedSums[0];
    partials[SSLPV_INJECT_STATS_VEC4 * gl_WorkGroupID.x + 1] = droppedSums[0];
  }
}

#version 460
// Ends a run of propagation steps, over the same work items. The propagation kernel
// accumulates two steps at a time (every other step), so the last step may still be
// missing from the accumulated light: it is added here when the GPU's step count says so
// (auto steps need no host round trip). When auto steps stopped, so is the estimated
// tail of the steps not run, tailScale times the last step's light. OUTPUT = 1
// (device-resident runs) also writes the total into the x-fastest grid that shading reads.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_EXT_control_flow_attributes : require

#include "shaders/lpv_step_common.glsl"

layout(local_size_x = SSLPV_TILE_X) in;
layout(constant_id = 1) const int OUTPUT = 0;

void main() {
  dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  const uvec4 item = items[gl_WorkGroupID.x];
  const int x = int(item.x + gl_SubgroupInvocationID);
  const int stepsRun = control.stepsRun;
  // Recorded after every submission of steps: only the end of the run counts.
  const bool finished = control.stopped != 0 || stepsRun == push.stepLimit;
  const bool addLast = stepsRun > 0 && stepsRun % 2 == push.leftoverParity;
  const vec3 tailScale = control.stopped != 0 ? vec3(control.tailScaleR, control.tailScaleG, control.tailScaleB)
                                              : vec3(0.0);
  const vec3 lastScale = tailScale + (addLast ? 1.0 : 0.0);
  const bool addTail = any(notEqual(tailScale, vec3(0.0)));
  const int runs = finished && (OUTPUT == 1 || addLast || addTail || push.chebyshev != SSLPV_CHEBYSHEV_NONE) ? 1 : 0;
  for (int once = 0; once < runs; ++once)  // a loop, not an if: lavapipe never skips an if
    for (int z = int(item.z); z < int(item.w); ++z)
      [[unroll]] for (int r = 0; r < ROWS; ++r) {
        const int y = int(item.y) + r;
        if (x >= dims.x || y >= dims.y) continue;
        const int i = cellIndex(x, y, z);
        for (int ch = 0; ch < 3; ++ch) {
          // The host binds the set whose sourceField holds the last step's light whenever
          // it is missing (always the same field for a given accumulation parity), so
          // otherwise the last step wrote the set's other field. Ring cells hold no light
          // in either grid.
          vec4 total;
          if (push.chebyshev != SSLPV_CHEBYSHEV_NONE) {
            // The last iterate (written by step stepsRun - 1 into the set's source field
            // when stepsRun is even) plus the injected light times its fresh gain.
            const vec4 iterate = stepsRun % 2 == 0 ? texelFetch(sourceField, 3 * i + ch) : texelFetch(otherField, 3 * i + ch);
            const float gain = texelFetch(factors, SSLPV_FACTOR_VEC4_PER_CELL * i + 3)[ch];
            total = iterate + gain * texelFetch(injectedField, 3 * linearIndex(x, y, z) + ch);
          } else {
            const vec4 lastField = addLast ? texelFetch(sourceField, 3 * i + ch) : texelFetch(otherField, 3 * i + ch);
            total = texelFetch(accumulatedIn, 3 * i + ch) + lastScale[ch] * lastField;
          }
          if (OUTPUT == 1) accumulatedOut[3 * linearIndex(x, y, z) + ch] = total;
          else accumulated[3 * i + ch] = total;
        }
      }
}

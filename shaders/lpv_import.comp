#version 460
// Copies the injected light (x-fastest, as injection writes it) into the propagator's
// first tiled field, over the work items: the cells that can hold light. One pass of
// gathers here lets every step read a sequential stream.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_EXT_control_flow_attributes : require

#include "shaders/lpv_step_common.glsl"

layout(local_size_x = SSLPV_TILE_X) in;

void main() {
  dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  const uvec4 item = items[gl_WorkGroupID.x];
  const int x = int(item.x + gl_SubgroupInvocationID);
  for (int z = int(item.z); z < int(item.w); ++z)
    [[unroll]] for (int r = 0; r < ROWS; ++r) {
      const int y = int(item.y) + r;
      if (x >= dims.x || y >= dims.y) continue;
      const int i = cellIndex(x, y, z), j = linearIndex(x, y, z);
      for (int ch = 0; ch < 3; ++ch) destination[3 * i + ch] = texelFetch(injectedField, 3 * j + ch);
    }
}

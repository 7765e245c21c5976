#version 460
// Per cell: inside from the parity of the crossings below its centre, coverage from its
// packed nearest-triangle word (vox_cellCoverage). Twin of the coverage loop in
// volume/lpv/voxelize_parity.cpp (parityInside).
#extension GL_GOOGLE_include_directive : require
#include "device_shared/voxelize_shared.h"

layout(local_size_x = SSLPV_VOX_CELL_GROUP) in;

layout(push_constant) uniform PushBlock { SSLPV_VOXELIZE_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;
layout(std430, binding = 2) readonly buffer Nearest { uint nearest[]; };
layout(std430, binding = 3) readonly buffer Parity { uint parity[]; };
layout(std430, binding = 4) writeonly buffer Coverage { float coverage[]; };

void main() {
  // Two-dimensional dispatch: a grid can hold more cells than 65535 workgroups of x.
  uint cell = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  uint columnCells = uint(push.dimsX) * uint(push.dimsY);
  if (cell >= columnCells * uint(push.dimsZ)) return;
  uint column = cell % columnCells;
  uint z = cell / columnCells;
  uint base = column * uint(push.wordsPerColumn);
  uint ones = 0u;
  for (uint w = 0u; w < (z >> 5u); ++w) ones += uint(bitCount(parity[base + w]));
  uint mask = (2u << (z & 31u)) - 1u;  // bits 0..z&31; 2u << 31 wraps to 0
  ones += uint(bitCount(parity[base + (z >> 5u)] & mask));
  coverage[cell] = vox_cellCoverage(nearest[cell], (ones & 1u) != 0u);
}

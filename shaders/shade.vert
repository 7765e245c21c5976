#version 460
// Shading rasterization (visibility): the mesh seen from the camera of shadeImage
// (volume/cpu/shade.cpp), vertices pulled from the mesh buffers (3 per triangle,
// non-indexed), projected so that pixel centres are exactly the CPU's camera rays. The
// fragment shader keeps the nearest triangle per pixel; shaders/shade.comp shades it.
#extension GL_GOOGLE_include_directive : require
#include "device_shared/shade_shared.h"

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(push_constant) uniform Push { GpuShadePush push; };

layout(location = 0) flat out uint triangleId;

void main() {
  const vec3 p = positions[indices[gl_VertexIndex]].xyz - push.eye.xyz;
  // The camera ray through pixel (x, y) has (right, up) / forward components
  // (u, v) = ((2 (x + 0.5) / width - 1) tanX, (1 - 2 (y + 0.5) / height) tanY), row 0 at
  // the top: dividing by tanX and -tanY gives normalized device coordinates (Vulkan's y
  // points down). Depth is reversed: near / distance along the view axis.
  gl_Position = vec4(dot(p, push.right.xyz) / push.forward.w, -dot(p, push.up.xyz) / push.right.w, push.eye.w,
                     dot(p, push.forward.xyz));
  // 0 stays "background" in the cleared image.
  triangleId = uint(gl_VertexIndex) / 3u + 1u;
}

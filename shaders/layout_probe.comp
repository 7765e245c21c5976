#version 460
// Test probe for tests/gpu/gpu_layout_test.cpp: copies every field of the shared records, read
// by name as GLSL lays them out, into a flat buffer in declaration order. The test fills
// the records from C++ with distinct values and checks each lands where C++ put it.
#extension GL_GOOGLE_include_directive : require
#include "device_shared/lpv_shared.h"

layout(local_size_x = 1) in;

layout(push_constant) uniform PushBlock { SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;
layout(std430, binding = 0) readonly buffer ControlIn { SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD) } control;
layout(std430, binding = 1) writeonly buffer Fields { uint fields[]; };

uint bitsOf(int v) { return uint(v); }
uint bitsOf(uint v) { return v; }
uint bitsOf(float v) { return floatBitsToUint(v); }

void main() {
  uint next = 0;
#define SSLPV_COPY_PUSH(type, name) fields[next++] = bitsOf(push.name);
  SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_COPY_PUSH)
#define SSLPV_COPY_CONTROL(type, name) fields[next++] = bitsOf(control.name);
  SSLPV_LPV_CONTROL_FIELDS(SSLPV_COPY_CONTROL)
}

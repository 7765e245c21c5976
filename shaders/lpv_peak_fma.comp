#version 460
// Peak arithmetic rate of the device for bench/gpu_propagation_bench.cpp: every lane runs
// 16 independent chains of vec4 fused multiply-adds (named variables, so nothing is an
// indexed array; enough chains to hide the FMA latency), so the rate is FMA throughput,
// not latency or memory: 128 flops per lane per iteration.
layout(local_size_x = 64) in;

layout(push_constant) uniform PushBlock { int iterations; } push;
layout(std430, binding = 0) writeonly buffer Result { vec4 result[]; };

#define CHAIN(k) vec4 a##k = vec4(seed + float(k), seed - float(k), seed * float(k), seed + 0.5);
#define STEP(k) a##k = fma(a##k, m, c);

void main() {
  const float seed = float(gl_GlobalInvocationID.x) * 1e-7;
  CHAIN(0) CHAIN(1) CHAIN(2) CHAIN(3) CHAIN(4) CHAIN(5) CHAIN(6) CHAIN(7)
  CHAIN(8) CHAIN(9) CHAIN(10) CHAIN(11) CHAIN(12) CHAIN(13) CHAIN(14) CHAIN(15)
  const vec4 m = vec4(0.999999), c = vec4(1e-6);
  for (int i = 0; i < push.iterations; ++i) {
    STEP(0) STEP(1) STEP(2) STEP(3) STEP(4) STEP(5) STEP(6) STEP(7)
    STEP(8) STEP(9) STEP(10) STEP(11) STEP(12) STEP(13) STEP(14) STEP(15)
  }
  // Keeps every chain alive.
  result[gl_GlobalInvocationID.x] = ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7)) + ((a8 + a9) + (a10 + a11)) +
                                    ((a12 + a13) + (a14 + a15));
}

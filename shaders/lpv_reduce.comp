#version 460
// Sums the propagation step's workgroup partial power sums into one row of step totals,
// counts the step, and applies the --steps auto rule of volume/propagate.cpp: stop once
// the step added less than `autoTolerance` of the power accumulated so far, in the worst
// channel. Keeping the decision on the GPU lets many steps go in one submission.
#extension GL_GOOGLE_include_directive : require
#include "volume/lpv_constants.h"
#include "shaders/lpv_shared.h"

layout(local_size_x = SSLPV_REDUCE_GROUP) in;

layout(push_constant) uniform PushBlock { SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;

layout(std430, binding = 4) readonly buffer PartialSums { vec4 partials[]; };
layout(std430, binding = 5) buffer Control { SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD) } control;
layout(std430, binding = 6) writeonly buffer StepTotals { vec4 totals[]; };

shared vec4 reduction[SSLPV_REDUCE_GROUP];

void main() {
  if (control.stopped != 0) return;
  const uint li = gl_LocalInvocationIndex;
  vec4 row[4];
  for (int k = 0; k < 4; ++k) {
    vec4 sum = vec4(0.0);
    for (uint g = li; g < uint(push.partialRows); g += SSLPV_REDUCE_GROUP) sum += partials[4 * g + k];
    reduction[li] = sum;
    barrier();
    for (uint s = SSLPV_REDUCE_GROUP / 2; s > 0; s >>= 1) {
      if (li < s) reduction[li] += reduction[li + s];
      barrier();
    }
    row[k] = reduction[0];
    barrier();
  }
  if (li != 0) return;
  for (int k = 0; k < 4; ++k) totals[4 * push.stepSlot + k] = row[k];

  const vec3 inGrid = row[3].xyz * float(SSLPV_FLUX_PER_C0);  // SSLPV_ENERGY_IN_GRID
  vec3 accumulatedPower = vec3(control.accumulatedPowerR, control.accumulatedPowerG, control.accumulatedPowerB);
  accumulatedPower += inGrid;
  control.accumulatedPowerR = accumulatedPower.r;
  control.accumulatedPowerG = accumulatedPower.g;
  control.accumulatedPowerB = accumulatedPower.b;
  control.stepsRun += 1;
  if (push.autoSteps != 0) {
    float worst = 0.0;
    for (int ch = 0; ch < 3; ++ch)
      if (accumulatedPower[ch] > 0.0) worst = max(worst, inGrid[ch] / accumulatedPower[ch]);
    if (worst < push.autoTolerance) control.stopped = 1;
  }
}

#version 460
// Sums the propagation step's per-item partial power sums into one row of step totals,
// counts the step, and applies the --steps auto rule of decideAutoStop()
// (volume/cpu/propagate.cpp): stop once, in every lit channel, the step added less than
// `autoTolerance` of the power accumulated so far and the geometric tail r/(1-r) times
// the step is below `autoTailTolerance` of it; the tail's scale is left in the control
// record for the accumulation. Keeping the decision on the GPU lets many steps go in one
// submission.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "device_shared/lpv_constants.h"
#include "device_shared/lpv_shared.h"

layout(local_size_x = SSLPV_REDUCE_GROUP) in;

layout(push_constant) uniform PushBlock { SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;

layout(std430, binding = 6) readonly buffer PartialSums { vec4 partials[]; };
layout(std430, binding = 7) coherent buffer Control { SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD) } control;
layout(std430, binding = 8) writeonly buffer StepTotals { vec4 totals[]; };

// One entry per subgroup (at least 1 lane per subgroup; the group is small).
shared vec4 subgroupTotals[SSLPV_ENERGY_VEC4S][SSLPV_REDUCE_GROUP];

/// chebyshevOmega() and chebyshevRate() of volume/cpu/propagate.cpp, in float.
float chebyshevOmega(int k, float rho) {
  if (!(rho > 0.0) || k < 1) return 1.0;
  return 2.0 / (1.0 + tanh(float(k) * acosh(1.0 / rho)) * sqrt(1.0 - rho * rho));
}
float chebyshevRate(float rho) { return rho > 0.0 ? rho / (1.0 + sqrt(max(0.0, 1.0 - rho * rho))) : 0.0; }

void main() {
  const int stopped = control.stopped;
  const uint li = gl_LocalInvocationIndex;
  // A loop, not an if: lavapipe skips a loop whose lanes are all inactive, never an if.
  for (int live = stopped; live == 0; live = 1) {
    for (int k = 0; k < SSLPV_ENERGY_VEC4S; ++k) {
      vec4 sum = vec4(0.0);
      for (uint g = li; g < uint(push.itemCount); g += SSLPV_REDUCE_GROUP) sum += partials[SSLPV_ENERGY_VEC4S * g + k];
      sum = subgroupAdd(sum);
      if (subgroupElect()) subgroupTotals[k][gl_SubgroupID] = sum;
    }
  }
  barrier();
  if (stopped != 0 || li != 0) return;
  vec4 row[SSLPV_ENERGY_VEC4S];
  for (int k = 0; k < SSLPV_ENERGY_VEC4S; ++k) {
    row[k] = vec4(0.0);
    for (uint s = 0; s < gl_NumSubgroups; ++s) row[k] += subgroupTotals[k][s];
    totals[SSLPV_ENERGY_VEC4S * push.stepSlot + k] = row[k];
  }

  if (push.chebyshev != SSLPV_CHEBYSHEV_NONE) {
    // runChebyshev() on the CPU.
    control.stepsRun += 1;
    const vec3 change = vec3(row[1].zw, row[2].x);                     // SSLPV_ENERGY_GATHERED
    const vec3 total = row[3].xyz * float(SSLPV_FLUX_PER_C0);          // SSLPV_ENERGY_IN_GRID
    vec3 rho = vec3(control.rhoR, control.rhoG, control.rhoB);
    if (push.chebyshev == SSLPV_CHEBYSHEV_PROBE) {
      // A probe step: the ratio of its power to the last one's estimates the radius.
      const vec3 previous = vec3(control.previousInGridR, control.previousInGridG, control.previousInGridB);
      for (int ch = 0; ch < 3; ++ch)
        rho[ch] = previous[ch] > 0.0 ? clamp(total[ch] / previous[ch], 0.0, float(SSLPV_CHEBYSHEV_MAX_RHO)) : 0.0;
      control.previousInGridR = total.r;
      control.previousInGridG = total.g;
      control.previousInGridB = total.b;
      control.rhoR = rho.r;
      control.rhoG = rho.g;
      control.rhoB = rho.b;
      control.omegaR = control.omegaG = control.omegaB = 1.0;  // the first iterate's
      // No light left before this step: converged (runChebyshev's `dark`).
      if (!(previous.r > 0.0) && !(previous.g > 0.0) && !(previous.b > 0.0)) control.stopped = 1;
      return;
    }
    const int k = control.iterates + 1;
    control.iterates = k;
    const vec3 lastChange = vec3(control.lastChangeR, control.lastChangeG, control.lastChangeB);
    vec3 logShrink = vec3(control.logShrinkR, control.logShrinkG, control.logShrinkB);
    bool converged = k > SSLPV_CHEBYSHEV_RATE_WINDOW;
    vec3 omega;
    vec3 markChange = vec3(control.markChangeR, control.markChangeG, control.markChangeB);
    vec3 markTotal = vec3(control.markTotalR, control.markTotalG, control.markTotalB);
    ivec3 sinceMark = ivec3(control.sinceMarkR, control.sinceMarkG, control.sinceMarkB);
    for (int ch = 0; ch < 3; ++ch) {
      omega[ch] = chebyshevOmega(k, rho[ch]);
      if (k > 1 && lastChange[ch] > 0.0 && change[ch] > 0.0)
        logShrink[ch] += (log(change[ch] / lastChange[ch]) - logShrink[ch]) / float(SSLPV_CHEBYSHEV_RATE_WINDOW);
      const float chTotal = row[3][ch];
      // StallWatch: the float floor, where the change stops halving and the total stays put.
      if (sinceMark[ch] >= 0) {
        if (sinceMark[ch] == 0 || change[ch] < 0.5 * markChange[ch]) {
          markChange[ch] = change[ch];
          markTotal[ch] = chTotal;
          sinceMark[ch] = 1;
        } else if (++sinceMark[ch] >= SSLPV_CHEBYSHEV_STALL_WINDOW) {
          sinceMark[ch] = abs(chTotal - markTotal[ch]) < push.autoTolerance * abs(chTotal) ? -1 : 0;
        }
      }
      // chebyshevConverged(): the light still to come, the change times rate / (1 - rate)
      // at the larger of the theoretical and the observed shrink, under autoTolerance of
      // the total, or the change float noise, or the floor.
      if (!(chTotal > 0.0) || !(change[ch] > float(SSLPV_AUTO_STEP_NEGLIGIBLE) * chTotal) || sinceMark[ch] < 0) continue;
      const float rate = max(chebyshevRate(rho[ch]), min(exp(logShrink[ch]), float(SSLPV_CHEBYSHEV_MAX_RHO)));
      if (!(change[ch] * rate / (1.0 - rate) < push.autoTolerance * chTotal)) converged = false;
    }
    control.lastChangeR = change.r;
    control.lastChangeG = change.g;
    control.lastChangeB = change.b;
    control.logShrinkR = logShrink.r;
    control.logShrinkG = logShrink.g;
    control.logShrinkB = logShrink.b;
    control.omegaR = omega.r;
    control.omegaG = omega.g;
    control.omegaB = omega.b;
    control.markChangeR = markChange.r;
    control.markChangeG = markChange.g;
    control.markChangeB = markChange.b;
    control.markTotalR = markTotal.r;
    control.markTotalG = markTotal.g;
    control.markTotalB = markTotal.b;
    control.sinceMarkR = sinceMark.r;
    control.sinceMarkG = sinceMark.g;
    control.sinceMarkB = sinceMark.b;
    if (converged) control.stopped = 1;
    return;
  }
  const vec3 inGrid = row[3].xyz * float(SSLPV_FLUX_PER_C0);                          // SSLPV_ENERGY_IN_GRID
  const vec3 source = vec3(row[3].w, row[4].xy) * float(SSLPV_FLUX_PER_C0);           // SSLPV_ENERGY_SOURCE
  vec3 accumulatedPower = vec3(control.accumulatedPowerR, control.accumulatedPowerG, control.accumulatedPowerB);
  vec3 previousInGrid = vec3(control.previousInGridR, control.previousInGridG, control.previousInGridB);
  // A device-resident run starts from the power of the injected light, as the CPU does.
  if (push.initPower != 0) accumulatedPower = previousInGrid = source;
  accumulatedPower += inGrid;
  control.accumulatedPowerR = accumulatedPower.r;
  control.accumulatedPowerG = accumulatedPower.g;
  control.accumulatedPowerB = accumulatedPower.b;
  control.previousInGridR = inGrid.r;
  control.previousInGridG = inGrid.g;
  control.previousInGridB = inGrid.b;
  control.stepsRun += 1;
  if (push.autoSteps != 0) {
    bool stop = true;
    vec3 tailScale = vec3(0.0);
    for (int ch = 0; ch < 3; ++ch) {
      // A dark or fully converged channel never holds up a stop.
      if (!(accumulatedPower[ch] > 0.0) || !(inGrid[ch] > float(SSLPV_AUTO_STEP_NEGLIGIBLE) * accumulatedPower[ch]))
        continue;
      const float ratio = previousInGrid[ch] > 0.0 ? inGrid[ch] / previousInGrid[ch] : 0.0;
      if (!(ratio < 1.0) || inGrid[ch] >= push.autoTolerance * accumulatedPower[ch]) {
        stop = false;
        continue;
      }
      tailScale[ch] = ratio / (1.0 - ratio);
      if (inGrid[ch] * tailScale[ch] >= push.autoTailTolerance * accumulatedPower[ch]) stop = false;
    }
    if (stop) {
      control.tailScaleR = tailScale.r;
      control.tailScaleG = tailScale.g;
      control.tailScaleB = tailScale.b;
      control.stopped = 1;
    }
  }
}

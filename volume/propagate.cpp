// LPV propagation on the CPU: gather from 6 neighbours through 5 faces each
// (Kaplanyan-Dachsbacher), then extinction and Henyey-Greenstein scattering per cell.
#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>

#include "volume/lpv_stages.h"
#include "volume/sh.h"

namespace sslpv {
namespace {

constexpr float kFront = float(SSLPV_FRONT_FACE_SOLID_ANGLE);
constexpr float kSide = float(SSLPV_SIDE_FACE_SOLID_ANGLE);
// Side faces are evaluated in the direction of their centres, (e_a ± 0.5 e_b)/sqrt(1.25).
const float kSideNorm = float(1.0 / std::sqrt(1.25));
// Re-emission as a cosine lobe of power Φ: (Φ/π)(C0, C1 n).
constexpr float kEmitDC = sh::kLobeC0 / sh::kPi;
constexpr float kEmitLinear = sh::kLobeC1 / sh::kPi;

/// Denormals appear as light decays over thousands of steps and make every operation on
/// them ~100x slower; flush them for the duration of a task and restore the caller's mode.
class FlushDenormals {
 public:
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }
  ~FlushDenormals() { _mm_setcsr(saved_); }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
  unsigned saved_;
};

/// Sum of Δω_f · max(0, I(ω_f)) over the 30 faces a cell sends light through.
inline float clampedFaceFlux(float c0, const float c[3]) {
  const float base = c0 * sh::kY00;
  float total = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    for (int sd = -1; sd <= 1; sd += 2) {
      const float along = sd * sh::kY1 * c[a];
      total += kFront * std::max(0.0f, base + along);
      const float alongSide = along * kSideNorm;
      const float h1 = 0.5f * sh::kY1 * c[b1] * kSideNorm, h2 = 0.5f * sh::kY1 * c[b2] * kSideNorm;
      total += kSide * (std::max(0.0f, base + alongSide + h1) + std::max(0.0f, base + alongSide - h1) +
                        std::max(0.0f, base + alongSide + h2) + std::max(0.0f, base + alongSide - h2));
    }
  }
  return total;
}

struct SliceSums {
  glm::dvec3 emitted{0.0}, clampRemoved{0.0}, gathered{0.0}, absorbed{0.0}, inGrid{0.0};
};

/// Rescales each active cell's coefficients so that the clamped face fluxes add up to
/// exactly the power it holds. Without it the clamp creates energy (a pure cosine lobe
/// gains ~14% per step); with it a step can only keep or lose power.
void normalizeEmission(const StepFactors& factors, ShGrid& field, std::vector<SliceSums>& sums) {
  const GridFrame& f = field.frame;
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    FlushDenormals flush;
    SliceSums& s = sums[z];
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (!factors.active[i]) continue;
        for (int ch = 0; ch < 3; ++ch) {
          float* c0 = field.plane(ch, 0);
          const float c[3] = {field.plane(ch, 1)[i], field.plane(ch, 2)[i], field.plane(ch, 3)[i]};
          const float power = c0[i] * sh::kFluxPerC0;
          const float raw = power > 0.0f ? clampedFaceFlux(c0[i], c) : 0.0f;
          const float scale = raw > 0.0f ? power / raw : 0.0f;
          for (int k = 0; k < 4; ++k) field.plane(ch, k)[i] *= scale;
          s.emitted[ch] += std::max(0.0f, power);
          s.clampRemoved[ch] += std::max(0.0f, raw - power);
        }
      }
  });
}

/// One gather into dst for the interior rows of slice z; applies the step factors,
/// accumulates, and records the slice's power sums.
void gatherSlice(int z, const StepFactors& factors, const ShGrid& src, ShGrid& dst, ShGrid& accumulated,
                 std::vector<float>& acc, SliceSums& s) {
  const GridFrame& f = src.frame;
  const int row = f.dims.x - 2;
  for (int y = 1; y < f.dims.y - 1; ++y) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    const std::size_t rowStart = f.index(1, y, z);
    for (int a = 0; a < 3; ++a) {
      const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
      for (int sd = -1; sd <= 1; sd += 2) {
        // Light travelling along sd*e_a comes from the neighbour at -sd*e_a.
        glm::ivec3 offset(0);
        offset[a] = -sd;
        const std::ptrdiff_t shift =
            (std::ptrdiff_t(offset.z) * f.dims.y + offset.y) * f.dims.x + offset.x;
        const std::size_t srcStart = std::size_t(std::ptrdiff_t(rowStart) + shift);
        for (int ch = 0; ch < 3; ++ch) {
          const float* __restrict c0 = src.plane(ch, 0) + srcStart;
          const float* __restrict ca = src.plane(ch, 1 + a) + srcStart;
          const float* __restrict cb1 = src.plane(ch, 1 + b1) + srcStart;
          const float* __restrict cb2 = src.plane(ch, 1 + b2) + srcStart;
          float* __restrict out0 = acc.data() + std::size_t(ch * 4) * row;
          float* __restrict outA = acc.data() + std::size_t(ch * 4 + 1 + a) * row;
          float* __restrict outB1 = acc.data() + std::size_t(ch * 4 + 1 + b1) * row;
          float* __restrict outB2 = acc.data() + std::size_t(ch * 4 + 1 + b2) * row;
          const float signedY1 = sd * sh::kY1;
          for (int x = 0; x < row; ++x) {
            const float base = c0[x] * sh::kY00;
            const float along = signedY1 * ca[x];
            const float front = std::max(0.0f, base + along);
            const float alongSide = base + along * kSideNorm;
            const float h1 = (0.5f * sh::kY1 * kSideNorm) * cb1[x];
            const float h2 = (0.5f * sh::kY1 * kSideNorm) * cb2[x];
            const float s1p = std::max(0.0f, alongSide + h1), s1m = std::max(0.0f, alongSide - h1);
            const float s2p = std::max(0.0f, alongSide + h2), s2m = std::max(0.0f, alongSide - h2);
            out0[x] += kEmitDC * (kFront * front + kSide * (s1p + s1m + s2p + s2m));
            outA[x] += float(sd) * kEmitLinear * kFront * front;
            outB1[x] += kEmitLinear * kSide * (s1p - s1m);
            outB2[x] += kEmitLinear * kSide * (s2p - s2m);
          }
        }
      }
    }
    for (int ch = 0; ch < 3; ++ch) {
      const float* dc = factors.dc[ch].data() + rowStart;
      const float* lin = factors.linear[ch].data() + rowStart;
      const unsigned char* active = factors.active.data() + rowStart;
      double gathered = 0.0, absorbed = 0.0, kept = 0.0;
      for (int k = 0; k < 4; ++k) {
        const float* in = acc.data() + std::size_t(ch * 4 + k) * row;
        float* out = dst.plane(ch, k) + rowStart;
        float* sum = accumulated.plane(ch, k) + rowStart;
        const float* factor = k == 0 ? dc : lin;
        for (int x = 0; x < row; ++x) {
          const float value = active[x] ? in[x] * factor[x] : 0.0f;
          out[x] = value;
          sum[x] += value;
        }
        if (k == 0)
          for (int x = 0; x < row; ++x)
            if (active[x]) {
              gathered += in[x];
              absorbed += in[x] * (1.0f - dc[x]);
              kept += out[x];
            }
      }
      s.gathered[ch] += gathered * sh::kFluxPerC0;
      s.absorbed[ch] += absorbed * sh::kFluxPerC0;
      s.inGrid[ch] += kept * sh::kFluxPerC0;
    }
  }
}

glm::dvec3 gridPower(const ShGrid& grid) {
  glm::dvec3 power(0.0);
  for (int ch = 0; ch < 3; ++ch) {
    double sum = 0.0;
    for (float c0 : grid.planes[ch * 4]) sum += c0;
    power[ch] = sum * sh::kFluxPerC0;
  }
  return power;
}

}  // namespace

StepFactors computeStepFactors(const MaterialGrid& material) {
  const GridFrame& f = material.frame;
  const std::size_t n = f.cellCount();
  StepFactors factors;
  for (int ch = 0; ch < 3; ++ch) {
    factors.dc[ch].assign(n, 0.0f);
    factors.linear[ch].assign(n, 0.0f);
  }
  factors.active.assign(n, 0);
  const double dx = f.cellSize;
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (!isActiveCell(material, x, y, z)) continue;
        factors.active[i] = 1;
        for (int ch = 0; ch < 3; ++ch) {
          const double sigmaT = material.sigmaT[i][ch], sigmaS = material.sigmaS[i][ch];
          const double e = std::exp(-sigmaT * dx);
          // Albedo of an empty cell is irrelevant (e = 1); guard the 0/0.
          const double albedo = sigmaT > 0.0 ? std::min(1.0, sigmaS / sigmaT) : 1.0;
          const double scattered = albedo * (1.0 - e);
          factors.dc[ch][i] = float(e + scattered);
          factors.linear[ch][i] = float(e + scattered * material.g[i]);
        }
      }
  });
  return factors;
}

PropagationResult propagate(const MaterialGrid& material, const StepFactors& factors, ShGrid& field,
                            ShGrid& accumulated, const PropagationOptions& options) {
  (void)material;
  PropagationResult result;
  const GridFrame& f = field.frame;
  result.initialPower = gridPower(field);
  for (int k = 0; k < ShGrid::kPlanes; ++k)
    std::transform(accumulated.planes[k].begin(), accumulated.planes[k].end(), field.planes[k].begin(),
                   accumulated.planes[k].begin(), std::plus<float>());
  glm::dvec3 accumulatedPower = result.initialPower;
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  if (f.dims.x < 3 || f.dims.y < 3 || f.dims.z < 3) return result;

  ShGrid next;
  next.resize(f);
  std::vector<SliceSums> sums(f.dims.z);
  const std::size_t rowFloats = std::size_t(ShGrid::kPlanes) * (f.dims.x - 2);
  for (int step = 0; step < maxSteps; ++step) {
    std::fill(sums.begin(), sums.end(), SliceSums{});
    normalizeEmission(factors, field, sums);
    tbb::parallel_for(tbb::blocked_range<int>(1, f.dims.z - 1), [&](const tbb::blocked_range<int>& zs) {
      FlushDenormals flush;
      std::vector<float> acc(rowFloats);
      for (int z = zs.begin(); z < zs.end(); ++z) gatherSlice(z, factors, field, next, accumulated, acc, sums[z]);
    });
    std::swap(field.planes, next.planes);
    ++result.stepsRun;

    SliceSums total;
    for (const SliceSums& s : sums) {
      total.emitted += s.emitted;
      total.clampRemoved += s.clampRemoved;
      total.gathered += s.gathered;
      total.absorbed += s.absorbed;
      total.inGrid += s.inGrid;
    }
    if (options.recordEnergy)
      result.energy.push_back(
          StepEnergy{total.inGrid, total.emitted - total.gathered, total.absorbed, total.clampRemoved});
    accumulatedPower += total.inGrid;
    if (options.autoSteps) {
      double worst = 0.0;
      for (int ch = 0; ch < 3; ++ch)
        if (accumulatedPower[ch] > 0.0) worst = std::max(worst, total.inGrid[ch] / accumulatedPower[ch]);
      if (worst < options.autoTolerance) break;
    }
  }
  return result;
}

}  // namespace sslpv

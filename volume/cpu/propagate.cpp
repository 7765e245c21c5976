// LPV propagation on the CPU: gather from 6 neighbours through 5 faces each
// (Kaplanyan-Dachsbacher), then extinction and Henyey-Greenstein scattering per cell.
// The face solid angles, the energy normalisation, the calibrated scheme's c0 stencil and
// the Chebyshev --steps auto are derived in docs/design.md §6.3, §6.7.1 and §6.9.
// One file past the usual ~600 lines on purpose: the gather kernels are inline templates
// instantiated by the step loops below, and keeping both in one translation unit is what
// lets the compiler inline and vectorize them without exporting the kernels in a header.
#include "volume/cpu/propagate.h"

#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>
#include <glm/vector_relational.hpp>
#include <limits>
#include <cmath>
#include <type_traits>

#include "volume/lpv/lpv_stages.h"
#include "volume/lpv/sh.h"

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
inline float clampedFaceFlux(float c0, float cx, float cy, float cz) {
  const float base = c0 * sh::kY00;
  const float c[3] = {cx, cy, cz};
  float total = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float h1 = (0.5f * sh::kY1 * kSideNorm) * c[(a + 1) % 3];
    const float h2 = (0.5f * sh::kY1 * kSideNorm) * c[(a + 2) % 3];
    for (int sd = -1; sd <= 1; sd += 2) {
      const float along = sd * sh::kY1 * c[a];
      total += kFront * std::max(0.0f, base + along);
      const float alongSide = base + along * kSideNorm;
      total += kSide * (std::max(0.0f, alongSide + h1) + std::max(0.0f, alongSide - h1) +
                        std::max(0.0f, alongSide + h2) + std::max(0.0f, alongSide - h2));
    }
  }
  return total;
}

struct SliceSums {
  glm::dvec3 emitted{0.0}, clampRemoved{0.0}, gathered{0.0}, absorbed{0.0}, inGrid{0.0};
};

/// Rescales each active cell's coefficients so that the clamped face fluxes add up to
/// exactly the power it holds. Without it the clamp creates energy (a pure cosine lobe
/// gains ~14% per step); with it a step can only keep or lose power. Inactive cells hold
/// no light, so the rows are processed whole (branch-free, vectorized).
void normalizeEmission(const StepFactors& factors, ShGrid& field, std::vector<SliceSums>& sums) {
  const GridFrame& f = field.frame;
  tbb::parallel_for(1, f.dims.z - 1, [&](int z) {
    FlushDenormals flush;
    SliceSums& s = sums[z];
    for (int y = 1; y < f.dims.y - 1; ++y) {
      if (!factors.rowActive[std::size_t(z) * f.dims.y + y]) continue;
      const std::size_t start = f.index(0, y, z);
      for (int ch = 0; ch < 3; ++ch) {
        float* __restrict c0 = field.plane(ch, 0) + start;
        float* __restrict cx = field.plane(ch, 1) + start;
        float* __restrict cy = field.plane(ch, 2) + start;
        float* __restrict cz = field.plane(ch, 3) + start;
        float emitted = 0.0f, removed = 0.0f;
#pragma omp simd reduction(+ : emitted, removed)
        for (int x = 0; x < f.dims.x; ++x) {
          const float power = std::max(0.0f, c0[x] * sh::kFluxPerC0);
          const float raw = clampedFaceFlux(c0[x], cx[x], cy[x], cz[x]);
          const float scale = raw > 0.0f ? power / raw : 0.0f;
          c0[x] *= scale;
          cx[x] *= scale;
          cy[x] *= scale;
          cz[x] *= scale;
          emitted += power;
          removed += std::max(0.0f, raw - power);
        }
        s.emitted[ch] += emitted;
        s.clampRemoved[ch] += removed;
      }
    }
  });
}

struct Gathered {
  float c0 = 0.0f, c[3] = {0.0f, 0.0f, 0.0f};
};

/// Adds what the neighbour at `j` sends through the 5 faces of the destination when light
/// travels along SD * e_A: the front face re-emits along e_A, the side faces along ±e_B.
/// `weight`: the sender's conductance (StepFactors::conductance; 1 where D is uniform).
template <int A, int SD>
inline void gatherFrom(const float* __restrict c0, const float* __restrict cx, const float* __restrict cy,
                       const float* __restrict cz, std::size_t j, float weight, Gathered& out) {
  constexpr int B1 = (A + 1) % 3, B2 = (A + 2) % 3;
  const float c1[3] = {weight * cx[j], weight * cy[j], weight * cz[j]};
  const float base = weight * c0[j] * sh::kY00;
  const float along = (SD * sh::kY1) * c1[A];
  const float front = std::max(0.0f, base + along);
  const float alongSide = base + along * kSideNorm;
  const float h1 = (0.5f * sh::kY1 * kSideNorm) * c1[B1];
  const float h2 = (0.5f * sh::kY1 * kSideNorm) * c1[B2];
  const float s1p = std::max(0.0f, alongSide + h1), s1m = std::max(0.0f, alongSide - h1);
  const float s2p = std::max(0.0f, alongSide + h2), s2m = std::max(0.0f, alongSide - h2);
  out.c0 += kEmitDC * (kFront * front + kSide * (s1p + s1m + s2p + s2m));
  out.c[A] += float(SD) * kEmitLinear * kFront * front;
  out.c[B1] += kEmitLinear * kSide * (s1p - s1m);
  out.c[B2] += kEmitLinear * kSide * (s2p - s2m);
}

/// One gather into dst for the interior rows of slice z; applies the step factors,
/// accumulates, and records the slice's power sums. All six neighbours are read in one
/// pass over the row so each output is written once.
/// kRetain: the calibrated scheme's boundary retention, kConduct: its varying diffusion
/// coefficient (template parameters so that the seed scheme's loop carries no test in its
/// body). Each face passes conductance[i] · conductance[j]: the sender's factor is applied
/// as it sends, the receiver's to all it gathers, as lpv_propagate.comp does.
template <bool kRetain, bool kConduct>
void gatherSlice(int z, const StepFactors& factors, const ShGrid& src, ShGrid& dst, ShGrid& accumulated,
                 SliceSums& s) {
  const GridFrame& f = src.frame;
  const std::size_t sx = 1, sy = std::size_t(f.dims.x), sz = std::size_t(f.dims.x) * f.dims.y;
  for (int y = 1; y < f.dims.y - 1; ++y) {
    // Inactive rows stay zero in both ping-pong buffers.
    if (!factors.rowActive[std::size_t(z) * f.dims.y + y]) continue;
    const std::size_t rowStart = f.index(1, y, z);
    const int row = f.dims.x - 2;
    for (int ch = 0; ch < 3; ++ch) {
      const float* __restrict c0 = src.plane(ch, 0);
      const float* __restrict cx = src.plane(ch, 1);
      const float* __restrict cy = src.plane(ch, 2);
      const float* __restrict cz = src.plane(ch, 3);
      const float* __restrict dc = factors.dc[ch].data();
      const float* __restrict lin = factors.linear[ch].data();
      const unsigned char* __restrict active = factors.active.data();
      const float* __restrict retain = kRetain ? factors.retention[ch].data() : nullptr;
      const float* __restrict conduct = kConduct ? factors.conductance[ch].data() : nullptr;
      float* __restrict out[4] = {dst.plane(ch, 0), dst.plane(ch, 1), dst.plane(ch, 2), dst.plane(ch, 3)};
      float* __restrict sum[4] = {accumulated.plane(ch, 0), accumulated.plane(ch, 1), accumulated.plane(ch, 2),
                                  accumulated.plane(ch, 3)};
      float gathered = 0.0f, absorbed = 0.0f, kept = 0.0f;
#pragma omp simd reduction(+ : gathered, absorbed, kept)
      for (int x = 0; x < row; ++x) {
        const std::size_t i = rowStart + x;
        const auto weight = [&](std::size_t j) { return kConduct ? conduct[j] : 1.0f; };
        Gathered g;
        gatherFrom<0, +1>(c0, cx, cy, cz, i - sx, weight(i - sx), g);
        gatherFrom<0, -1>(c0, cx, cy, cz, i + sx, weight(i + sx), g);
        gatherFrom<1, +1>(c0, cx, cy, cz, i - sy, weight(i - sy), g);
        gatherFrom<1, -1>(c0, cx, cy, cz, i + sy, weight(i + sy), g);
        gatherFrom<2, +1>(c0, cx, cy, cz, i - sz, weight(i - sz), g);
        gatherFrom<2, -1>(c0, cx, cy, cz, i + sz, weight(i + sz), g);
        const float on = active[i] ? 1.0f : 0.0f;
        // The boundary's share of what this cell sent toward outside neighbours: the DC an
        // isotropic cell sends one neighbour, times ρ per outside neighbour (with a varying
        // D, all the cell keeps, per its conductance²: the cell sends conductance · c0).
        if constexpr (kRetain)
          g.c0 += retain[i] * (kEmitDC * (kFront + 4.0f * kSide) * sh::kY00) * (weight(i) * c0[i]);
        if constexpr (kConduct) {
          g.c0 *= conduct[i];
          for (float& c : g.c) c *= conduct[i];
        }
        // A negative retention drains at most what the cell gathered: a cell driven below
        // zero would emit nothing next step anyway, but its negative light would enter the
        // accumulated sum and the power balance (the lattice would hand back more power
        // than was injected once the clamp zeroes it).
        if constexpr (kRetain) {
          const float holds = g.c0 > 0.0f ? 1.0f : 0.0f;
          g.c0 *= holds;
          for (float& c : g.c) c *= holds;
        }
        const float v0 = on * g.c0 * dc[i];
        const float v1 = on * g.c[0] * lin[i], v2 = on * g.c[1] * lin[i], v3 = on * g.c[2] * lin[i];
        out[0][i] = v0;
        out[1][i] = v1;
        out[2][i] = v2;
        out[3][i] = v3;
        sum[0][i] += v0;
        sum[1][i] += v1;
        sum[2][i] += v2;
        sum[3][i] += v3;
        gathered += on * g.c0;
        absorbed += on * g.c0 * (1.0f - dc[i]);
        kept += v0;
      }
      s.gathered[ch] += double(gathered) * sh::kFluxPerC0;
      s.absorbed[ch] += double(absorbed) * sh::kFluxPerC0;
      s.inGrid[ch] += double(kept) * sh::kFluxPerC0;
    }
  }
}

/// What an isotropic cell's c0 sends each of its six neighbours' c0 per step: its power
/// split six ways and re-emitted as a cosine lobe, kEmitDC · kFluxPerC0 / 6 (= 1/6).
/// lpv_transfer.glsl uses the same constant.
constexpr float kIsotropicShare = float(SSLPV_ISOTROPIC_NEIGHBOUR_SHARE);

/// What cell i gathers under the isotropic steps, before its survival: the share of the
/// six neighbours' c0 (and, with retention, ρ_i of its own) times the faces'
/// conductances, w_i (Σ_j w_j c_j + ρ_i w_i c_i) / 6. kClamp: a cell driven below zero
/// sends nothing (the plain steps, as the clamp's scale 0 makes it in normalizeEmission);
/// without it the operator is linear (the Chebyshev iterates).
template <bool kRetain, bool kConduct, bool kClamp>
inline float isotropicGather(const float* __restrict c0, const float* __restrict retain,
                             const float* __restrict conduct, std::size_t i, std::size_t sy, std::size_t sz) {
  const auto sent = [&](std::size_t j) {
    const float light = kClamp ? std::max(0.0f, c0[j]) : c0[j];
    return kConduct ? conduct[j] * light : light;
  };
  float g = sent(i - 1) + sent(i + 1) + sent(i - sy) + sent(i + sy) + sent(i - sz) + sent(i + sz);
  if constexpr (kRetain) g += retain[i] * sent(i);
  g *= kIsotropicShare;
  if constexpr (kConduct) g *= conduct[i];
  return g;
}

/// Calls body(std::bool_constant<kRetain>, std::bool_constant<kConduct>) for the factors'
/// boundary and diffusivity variant, so that each kernel's loop carries no test for them
/// (the seed scheme's neither; a varying D implies the retention array).
template <typename Body>
void withBoundaryVariant(const StepFactors& factors, Body&& body) {
  if (!factors.conductance[0].empty())
    body(std::true_type{}, std::true_type{});
  else if (!factors.retention[0].empty())
    body(std::true_type{}, std::false_type{});
  else
    body(std::false_type{}, std::false_type{});
}

/// gatherSlice for a field without linear band, in a scheme whose steps give it none
/// (the calibrated one: linear factors 0, isotropic injection). Every lobe is then the
/// same in all six directions and the clamped face fluxes are exact, so a step reduces to
/// a 7-point stencil on c0: new_i = on · dc · w_i (Σ_j w_j c_j⁺ + ρ_i w_i c_i⁺) / 6, with
/// c⁺ = max(0, c0) (a cell driven below zero emits nothing, as the clamp's scale 0 makes
/// it in normalizeEmission) and w the conductance. The same light as gatherSlice up to
/// float rounding, for a quarter of the memory traffic and no clamps; the normalization
/// pass is folded in. The linear planes stay zero and are not touched.
template <bool kRetain, bool kConduct>
void gatherSliceIsotropic(int z, const StepFactors& factors, const ShGrid& src, ShGrid& dst, ShGrid& accumulated,
                          SliceSums& s) {
  const GridFrame& f = src.frame;
  const std::size_t sy = std::size_t(f.dims.x), sz = std::size_t(f.dims.x) * f.dims.y;
  for (int y = 1; y < f.dims.y - 1; ++y) {
    if (!factors.rowActive[std::size_t(z) * f.dims.y + y]) continue;
    const std::size_t rowStart = f.index(1, y, z);
    const int row = f.dims.x - 2;
    for (int ch = 0; ch < 3; ++ch) {
      const float* __restrict c0 = src.plane(ch, 0);
      const float* __restrict dc = factors.dc[ch].data();
      const unsigned char* __restrict active = factors.active.data();
      const float* __restrict retain = kRetain ? factors.retention[ch].data() : nullptr;
      const float* __restrict conduct = kConduct ? factors.conductance[ch].data() : nullptr;
      float* __restrict out = dst.plane(ch, 0);
      float* __restrict sum = accumulated.plane(ch, 0);
      float emitted = 0.0f, gathered = 0.0f, absorbed = 0.0f, kept = 0.0f;
#pragma omp simd reduction(+ : emitted, gathered, absorbed, kept)
      for (int x = 0; x < row; ++x) {
        const std::size_t i = rowStart + x;
        // Drained to zero at most, as in gatherSlice.
        const float g = std::max(0.0f, isotropicGather<kRetain, kConduct, true>(c0, retain, conduct, i, sy, sz));
        const float on = active[i] ? 1.0f : 0.0f;
        const float v0 = on * g * dc[i];
        out[i] = v0;
        sum[i] += v0;
        emitted += std::max(0.0f, c0[i]);
        gathered += on * g;
        absorbed += on * g * (1.0f - dc[i]);
        kept += v0;
      }
      s.emitted[ch] += double(emitted) * sh::kFluxPerC0;
      s.gathered[ch] += double(gathered) * sh::kFluxPerC0;
      s.absorbed[ch] += double(absorbed) * sh::kFluxPerC0;
      s.inGrid[ch] += double(kept) * sh::kFluxPerC0;
    }
  }
}

/// Power sums of one slice of a Chebyshev iterate, per channel.
struct ChebyshevSums {
  glm::dvec3 change{0.0};  ///< Σ |x_{k+1} - x_k| over active cells (c0)
  glm::dvec3 total{0.0};   ///< Σ x_{k+1}
  /// kLocal only: the largest |x_{k+1} - x_k| / max(|x_{k+1}|, floor) over active cells.
  glm::dvec3 localChange{0.0};
};

/// One iterate of the Chebyshev semi-iteration for x = (I - T)^-1 y on the isotropic
/// stencil of gatherSliceIsotropic (without its clamp: the iterates approach the
/// converged light from both sides, and T must stay linear for the weights to hold):
/// x_{k+1} = ω (T x_k + sourceWeight · y - x_{k-1}) + x_{k-1}, written over x_{k-1} in
/// `older` (each cell reads its own old value only; neighbours are read from `current`).
/// A probe step is ω = 1 with sourceWeight 0, as lpv_propagate.comp's.
using ChannelPlanes = std::array<std::vector<float>, 3>;  ///< one c0 plane per channel

/// kLocal: also the largest change relative to the cell's own light (or `floor`, where
/// brighter) over the cells of `shell` (PropagationWarmStart::shell).
template <bool kRetain, bool kConduct, bool kLocal>
void chebyshevSlice(int z, const GridFrame& f, const StepFactors& factors, const ChannelPlanes& current,
                    ChannelPlanes& older, const ChannelPlanes& source, const glm::vec3& omega, float sourceWeight,
                    const glm::vec3& floor, const unsigned char* shell, ChebyshevSums& s) {
  const std::size_t sy = std::size_t(f.dims.x), sz = std::size_t(f.dims.x) * f.dims.y;
  for (int y = 1; y < f.dims.y - 1; ++y) {
    if (!factors.rowActive[std::size_t(z) * f.dims.y + y]) continue;
    const std::size_t rowStart = f.index(1, y, z);
    const int row = f.dims.x - 2;
    for (int ch = 0; ch < 3; ++ch) {
      const float* __restrict x = current[ch].data();
      const float* __restrict b = source[ch].data();
      float* __restrict out = older[ch].data();
      const float* __restrict dc = factors.dc[ch].data();
      const unsigned char* __restrict active = factors.active.data();
      const float* __restrict retain = kRetain ? factors.retention[ch].data() : nullptr;
      const float* __restrict conduct = kConduct ? factors.conductance[ch].data() : nullptr;
      const float w = omega[ch], lightFloor = floor[ch];
      float change = 0.0f, total = 0.0f, local = 0.0f;
#pragma omp simd reduction(+ : change, total) reduction(max : local)
      for (int k = 0; k < row; ++k) {
        const std::size_t i = rowStart + k;
        const float g = isotropicGather<kRetain, kConduct, false>(x, retain, conduct, i, sy, sz);
        const float on = active[i] ? 1.0f : 0.0f;
        const float next = on * (w * (g * dc[i] + sourceWeight * b[i] - out[i]) + out[i]);
        out[i] = next;
        change += std::abs(next - x[i]);
        total += next;
        if constexpr (kLocal)
          local = std::max(local, (shell[i] ? std::abs(next - x[i]) : 0.0f) / std::max(std::abs(next), lightFloor));
      }
      s.change[ch] += double(change);
      s.total[ch] += double(total);
      s.localChange[ch] = std::max(s.localChange[ch], double(local));
    }
  }
}

/// Does the field hold any linear band? A field without one stays without one under a
/// scheme whose linear factors are all 0.
bool hasLinearBand(const ShGrid& field) {
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 1; k < 4; ++k)
      for (float c : field.planes[ch * 4 + k])
        if (c != 0.0f) return true;
  return false;
}

}  // namespace

namespace {

/// One --steps auto decision (PropagationOptions::autoTolerance), per channel from the
/// power in the grid after this step and the previous one (W) and the power accumulated
/// so far including this step. lpv_reduce.comp applies the same rule on the GPU.
struct AutoStepDecision {
  bool stop = false;
  glm::dvec3 tailScale{0.0};  ///< when stopping: r/(1-r) per channel (0 for dark channels)
};
AutoStepDecision decideAutoStop(const glm::dvec3& inGrid, const glm::dvec3& previousInGrid,
                                const glm::dvec3& accumulatedPower, double stepTolerance, double tailTolerance) {
  AutoStepDecision decision;
  decision.stop = true;
  for (int ch = 0; ch < 3; ++ch) {
    // A dark or fully converged channel never holds up a stop.
    if (!(accumulatedPower[ch] > 0.0) || !(inGrid[ch] > SSLPV_AUTO_STEP_NEGLIGIBLE * accumulatedPower[ch])) continue;
    const double ratio = previousInGrid[ch] > 0.0 ? inGrid[ch] / previousInGrid[ch] : 0.0;
    if (!(ratio < 1.0) || inGrid[ch] >= stepTolerance * accumulatedPower[ch]) {
      decision.stop = false;
      continue;
    }
    decision.tailScale[ch] = ratio / (1.0 - ratio);
    if (inGrid[ch] * decision.tailScale[ch] >= tailTolerance * accumulatedPower[ch]) decision.stop = false;
  }
  if (!decision.stop) decision.tailScale = glm::dvec3(0.0);
  return decision;
}

/// accumulated += tailScale[ch] × lastField, per channel: the steps an auto stop skips.
void addTail(const ShGrid& lastField, const glm::dvec3& tailScale, ShGrid& accumulated) {
  for (int ch = 0; ch < 3; ++ch) {
    if (tailScale[ch] == 0.0) continue;
    const auto scale = float(tailScale[ch]);
    for (int sh = 0; sh < 4; ++sh) {
      const std::vector<float>& from = lastField.planes[ch * 4 + sh];
      std::vector<float>& to = accumulated.planes[ch * 4 + sh];
      for (std::size_t i = 0; i < to.size(); ++i) to[i] += scale * from[i];
    }
  }
}

}  // namespace

double chebyshevOmega(int k, double rho) {
  if (!(rho > 0.0) || k < 1) return 1.0;
  return 2.0 / (1.0 + std::tanh(k * std::acosh(1.0 / rho)) * std::sqrt(1.0 - rho * rho));
}

double chebyshevRate(double rho) { return rho > 0.0 ? rho / (1.0 + std::sqrt(std::max(0.0, 1.0 - rho * rho))) : 0.0; }

namespace {

/// The stop of --steps auto for the semi-iteration, per channel from the last iterate's
/// change and total: every lit channel's light still to come, estimated as the change
/// times rate / (1 - rate) (its error shrinks by about `rate` per step), is below
/// `tolerance` of its total, or the change is float noise. No tail is added: unlike the
/// plain steps' geometric tail, the estimate is only a bound. lpv_reduce.comp applies
/// the same rule.
bool chebyshevConverged(const ChebyshevSums& sums, const glm::dvec3& rate, double tolerance, const glm::bvec3& stalled) {
  for (int ch = 0; ch < 3; ++ch) {
    const double total = sums.total[ch], change = sums.change[ch];
    if (!(total > 0.0) || !(change > SSLPV_AUTO_STEP_NEGLIGIBLE * total) || stalled[ch]) continue;
    if (!(change * rate[ch] / (1.0 - rate[ch]) < tolerance * total)) return false;
  }
  return true;
}

/// Per channel, whether the semi-iteration has reached its float floor
/// (SSLPV_CHEBYSHEV_STALL_WINDOW): the change has not halved over the window while the
/// total moved by under `tolerance` of itself. There the rate estimate tends to 1 (the
/// change no longer shrinks) and the usual stop would never come. A channel at its floor
/// stays there (sinceMark -1). lpv_reduce.comp keeps the same marks in its control record.
struct StallWatch {
  glm::dvec3 markChange{0.0}, markTotal{0.0};
  glm::ivec3 sinceMark{0};
  glm::bvec3 update(const ChebyshevSums& sums, double tolerance) {
    for (int ch = 0; ch < 3; ++ch) {
      const double change = sums.change[ch], total = sums.total[ch];
      if (sinceMark[ch] < 0) continue;
      if (sinceMark[ch] == 0 || change < 0.5 * markChange[ch]) {
        markChange[ch] = change;
        markTotal[ch] = total;
        sinceMark[ch] = 1;
      } else if (++sinceMark[ch] >= SSLPV_CHEBYSHEV_STALL_WINDOW) {
        // At the floor, or slow progress (a new window).
        sinceMark[ch] = std::abs(total - markTotal[ch]) < tolerance * std::abs(total) ? -1 : 0;
      }
    }
    return glm::lessThan(sinceMark, glm::ivec3(0));
  }
};

/// PropagationWarmStart::shell: the active cells within two cells (along every axis) of
/// an inactive one, by a separable dilation of the inactive cells.
std::vector<unsigned char> shadedShell(const GridFrame& f, const std::vector<unsigned char>& active) {
  std::vector<unsigned char> near(active.size());
  for (std::size_t i = 0; i < near.size(); ++i) near[i] = !active[i];
  const std::size_t strides[3] = {1, std::size_t(f.dims.x), std::size_t(f.dims.x) * f.dims.y};
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<unsigned char> dilated(near.size(), 0);
    for (int z = 0; z < f.dims.z; ++z)
      for (int y = 0; y < f.dims.y; ++y)
        for (int x = 0; x < f.dims.x; ++x) {
          const int c[3] = {x, y, z};
          const std::size_t i = f.index(x, y, z);
          for (int d = -2; d <= 2 && !dilated[i]; ++d) {
            const int at = c[axis] + d;
            if (at >= 0 && at < f.dims[axis]) dilated[i] = near[std::size_t(std::ptrdiff_t(i) + d * std::ptrdiff_t(strides[axis]))];
          }
        }
    near.swap(dilated);
  }
  for (std::size_t i = 0; i < near.size(); ++i) near[i] = near[i] && active[i];
  return near;
}

/// Runs the semi-iteration for x = (I - T)^-1 y, y the light of the first step (in
/// `field`, which ends holding the last iterate), adding x - y to `accumulated`, which
/// already holds y. T is similar to a symmetric operator (T = S W (K + R) W / 6: survival,
/// conductance, neighbours, retention), so its spectrum is real, within [-max s, max s];
/// with the weights for any rho < 1 the error of each mode λ shrinks as
/// T_k(λ / rho) / T_k(1 / rho), which goes to 0 for every |λ| < 1: a rho under the true
/// radius only converges more slowly, so the probe's estimate from below is safe. The
/// iterates start from the last probe step's light, or, warm, from a previous frame's
/// converged light (options.warmStart); any start converges.
void runChebyshev(const StepFactors& factors, ShGrid& field, ShGrid& accumulated, const PropagationOptions& options,
                  int maxSteps, PropagationResult& result) {
  const GridFrame& f = field.frame;
  ChannelPlanes source, current, older;
  for (int ch = 0; ch < 3; ++ch) {
    source[ch] = field.planes[std::size_t(ch) * 4];
    current[ch] = source[ch];
    older[ch].assign(source[ch].size(), 0.0f);  // x_{-1}: weight 1 cancels it
  }
  std::vector<ChebyshevSums> sums(f.dims.z);
  // Warm runs also watch each cell's own change (localFloor > 0; see the stop below).
  glm::vec3 localFloor(0.0f);
  PropagationWarmStart* warm = options.warmStart;
  const auto iterate = [&](const glm::vec3& omega, float sourceWeight) {
    std::fill(sums.begin(), sums.end(), ChebyshevSums{});
    const bool local = localFloor != glm::vec3(0.0f);
    tbb::parallel_for(tbb::blocked_range<int>(1, f.dims.z - 1), [&](const tbb::blocked_range<int>& zs) {
      FlushDenormals flush;
      withBoundaryVariant(factors, [&](auto retain, auto conduct) {
        constexpr bool kRetain = decltype(retain)::value, kConduct = decltype(conduct)::value;
        for (int z = zs.begin(); z < zs.end(); ++z) {
          if (local)
            chebyshevSlice<kRetain, kConduct, true>(z, f, factors, current, older, source, omega, sourceWeight,
                                                    localFloor, warm->shell.data(), sums[z]);
          else
            chebyshevSlice<kRetain, kConduct, false>(z, f, factors, current, older, source, omega, sourceWeight,
                                                     localFloor, nullptr, sums[z]);
        }
      });
    });
    std::swap(current, older);
    ++result.stepsRun;
    ChebyshevSums total;
    for (const ChebyshevSums& s : sums) {
      total.change += s.change;
      total.total += s.total;
      total.localChange = glm::max(total.localChange, s.localChange);
    }
    return total;
  };
  glm::dvec3 previous(0.0), rho(0.0);
  for (int ch = 0; ch < 3; ++ch) for (float v : source[ch]) previous[ch] += v;
  // A warm start needs a source: with none the cold path's probe finds the scene dark
  // and stops at once, where iterating the old light down to zero would take as long as
  // a cold run.
  const bool lit = previous.x > 0.0 || previous.y > 0.0 || previous.z > 0.0;
  bool started = warm && warm->holds(f) && lit;
  // A radius of 0 (a channel that was dark) would make the stop rule's rate 0 and end the
  // run before the light has spread.
  for (int ch = 0; ch < 3 && started; ++ch)
    if (previous[ch] > 0.0 && !(warm->rho[ch] > 0.0)) started = false;
  // A coarser grid's light is a cold run's start in all but its error: spread over the
  // whole light, like a cold start's, so the cold stop rule holds for it.
  result.coarseStarted = started && warm->fromCoarserGrid;
  result.warmStarted = started && !result.coarseStarted;
  if (started) {
    if (result.warmStarted && warm->shell.size() != f.cellCount()) warm->shell = shadedShell(f, factors.active);
    std::size_t activeCells = 0;
    for (unsigned char a : factors.active) activeCells += a;
    for (int ch = 0; ch < 3; ++ch) {
      current[ch] = warm->light[ch];
      double light = 0.0;
      for (float v : current[ch]) light += v;
      // Cells under this share of the mean cell's light do not hold up the stop.
      if (result.warmStarted)
        localFloor[ch] = float(std::max(SSLPV_WARM_START_LOCAL_FLOOR * light / double(std::max<std::size_t>(activeCells, 1)),
                                      double(std::numeric_limits<float>::min())));
    }
    rho = warm->rho;
    if (result.coarseStarted) {
      // A coarser grid's light has the right shape but not the right scale (each grid's
      // calibration has its own discretisation) nor the fine grid's radius. The scale:
      // per channel the multiple α of the guess whose losses balance the source,
      // α (Σx - ΣTx) = Σy (one plain step gives ΣTx). The radius: the probe's plain steps,
      // from the guess rather than from y. The guess is (nearly) the converged light, in
      // which each mode is weighted by 1/(1 - λ), so its power ratio approaches the
      // largest λ within the probe's steps, where y, concentrated under the surface, is
      // dominated by fast modes (on the frame benchmark's sphere at 64³, 16 steps give
      // 0.990 from the guess, 0.973 from y and 0.996 only after 256 steps from y); the
      // radius decides how fast the slowest modes converge.
      ChannelPlanes guess = current;
      glm::dvec3 guessTotal(0.0);
      for (int ch = 0; ch < 3; ++ch) for (float v : guess[ch]) guessTotal[ch] += v;
      const ChebyshevSums stepped = iterate(glm::vec3(1.0f), 0.0f);
      for (int ch = 0; ch < 3; ++ch) {
        const double lost = guessTotal[ch] - stepped.total[ch];
        const float alpha = lost > 0.0 && previous[ch] > 0.0 ? float(previous[ch] / lost) : 1.0f;
        for (float& v : guess[ch]) v *= alpha;
      }
      current = guess;
      glm::dvec3 before(0.0);
      for (int ch = 0; ch < 3; ++ch) for (float v : guess[ch]) before[ch] += v;
      for (int k = 0; k < SSLPV_CHEBYSHEV_PROBE_STEPS && result.stepsRun < maxSteps; ++k) {
        const ChebyshevSums t = iterate(glm::vec3(1.0f), 0.0f);
        for (int ch = 0; ch < 3; ++ch)
          rho[ch] = before[ch] > 0.0 ? std::clamp(t.total[ch] / before[ch], 0.0, SSLPV_CHEBYSHEV_MAX_RHO) : 0.0;
        before = t.total;
      }
      current = std::move(guess);
      for (int ch = 0; ch < 3; ++ch) std::fill(older[ch].begin(), older[ch].end(), 0.0f);
    }
  }
  // Probe (cold start): plain steps from y, whose power ratio approaches the spectral
  // radius of the modes that carry the light from below (an estimate under the radius is
  // safe: the iteration still converges, more slowly).
  // Where no light is left (a dark scene, or one absorbed within the probe) the light is
  // already converged: stop after the probe step that finds it so, as the GPU does.
  bool dark = false;
  for (int k = 0; !started && k < SSLPV_CHEBYSHEV_PROBE_STEPS && result.stepsRun < maxSteps && !dark;
       ++k) {
    const ChebyshevSums t = iterate(glm::vec3(1.0f), 0.0f);
    dark = !(previous.x > 0.0) && !(previous.y > 0.0) && !(previous.z > 0.0);
    for (int ch = 0; ch < 3; ++ch)
      rho[ch] = previous[ch] > 0.0 ? std::clamp(t.total[ch] / previous[ch], 0.0, SSLPV_CHEBYSHEV_MAX_RHO) : 0.0;
    previous = t.total;
  }
  const glm::dvec3 rate(chebyshevRate(rho.x), chebyshevRate(rho.y), chebyshevRate(rho.z));
  // The observed shrink per iterate: a running mean of log(change / last change).
  glm::dvec3 lastChange(0.0), logShrink(0.0);
  StallWatch stall;
  bool converged = dark;
  for (int k = 1; result.stepsRun < maxSteps && !dark; ++k) {
    glm::vec3 omega(1.0f);
    for (int ch = 0; ch < 3; ++ch) omega[ch] = float(chebyshevOmega(k - 1, rho[ch]));
    const ChebyshevSums total = iterate(omega, 1.0f);
    glm::dvec3 effective = rate;
    for (int ch = 0; ch < 3; ++ch) {
      if (k > 1 && lastChange[ch] > 0.0 && total.change[ch] > 0.0)
        logShrink[ch] += (std::log(total.change[ch] / lastChange[ch]) - logShrink[ch]) / SSLPV_CHEBYSHEV_RATE_WINDOW;
      // Where modes above the probe's estimate shrink more slowly than the theory says.
      effective[ch] = std::max(rate[ch], std::min(std::exp(logShrink[ch]), SSLPV_CHEBYSHEV_MAX_RHO));
    }
    lastChange = total.change;
    const glm::bvec3 stalled = stall.update(total, options.autoTolerance);
    // A cold start's error is spread over the whole light, so bounding its sum bounds every
    // region's; a warm start's sits where the frame changed, so its stop also bounds each
    // cell's (PropagationOptions::warmLocalTolerance).
    glm::dvec3 localTail(0.0);
    if (result.warmStarted)
      for (int ch = 0; ch < 3; ++ch) localTail[ch] = total.localChange[ch] * effective[ch] / (1.0 - effective[ch]);
    const bool localConverged = glm::all(glm::lessThan(localTail, glm::dvec3(options.warmLocalTolerance)) || stalled);
    if (k > SSLPV_CHEBYSHEV_RATE_WINDOW && localConverged &&
        chebyshevConverged(total, effective, options.autoTolerance, stalled)) {
      converged = true;
      break;
    }
  }
  result.capped = !converged;
  if (warm) {
    warm->frame = f;
    warm->rho = rho;
    warm->fromCoarserGrid = false;
    for (int ch = 0; ch < 3; ++ch) warm->light[ch] = current[ch];
  }
  for (int ch = 0; ch < 3; ++ch) {
    float* sum = accumulated.plane(ch, 0);
    for (std::size_t i = 0; i < current[ch].size(); ++i) sum[i] += current[ch][i] - source[ch][i];
    field.planes[std::size_t(ch) * 4] = std::move(current[ch]);
  }
}

}  // namespace

std::array<float, 6> neighbourFaceFlux(float c0, float cx, float cy, float cz) {
  const float c1[3] = {cx, cy, cz};
  const float base = c0 * sh::kY00;
  std::array<float, 6> flux{};
  for (int a = 0; a < 3; ++a) {
    const float h1 = (0.5f * sh::kY1 * kSideNorm) * c1[(a + 1) % 3];
    const float h2 = (0.5f * sh::kY1 * kSideNorm) * c1[(a + 2) % 3];
    for (int sd = -1; sd <= 1; sd += 2) {
      const float along = sd * sh::kY1 * c1[a];
      const float alongSide = base + along * kSideNorm;
      flux[2 * a + (sd > 0 ? 1 : 0)] =
          kFront * std::max(0.0f, base + along) +
          kSide * (std::max(0.0f, alongSide + h1) + std::max(0.0f, alongSide - h1) +
                   std::max(0.0f, alongSide + h2) + std::max(0.0f, alongSide - h2));
    }
  }
  return flux;
}

PropagationResult propagate(const MaterialGrid& material, const StepFactors& factors, ShGrid& field,
                            ShGrid& accumulated, const PropagationOptions& options) {
  (void)material;
  PropagationResult result;
  const GridFrame& f = field.frame;
  result.initialPower = gridPower(field);
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  const bool stepping = propagationSteps(f, options);
  addInjected(stepping ? factors.freshGain : std::array<std::vector<float>, 3>{}, field, accumulated);
  glm::dvec3 accumulatedPower = result.initialPower;
  glm::dvec3 previousInGrid = result.initialPower;
  if (!stepping) return result;

  ShGrid next;
  next.resize(f);
  std::vector<SliceSums> sums(f.dims.z);
  // After one full step a scheme with zero linear factors leaves no linear band, so
  // every later step (and the first, when the injection was isotropic) is isotropic.
  const bool keepsIsotropic = options.isotropicFastPath && keepsCellsIsotropic(factors);
  bool isotropic = keepsIsotropic && !hasLinearBand(field);
  for (int step = 0; step < maxSteps; ++step) {
    std::fill(sums.begin(), sums.end(), SliceSums{});
    if (!isotropic) normalizeEmission(factors, field, sums);
    tbb::parallel_for(tbb::blocked_range<int>(1, f.dims.z - 1), [&](const tbb::blocked_range<int>& zs) {
      FlushDenormals flush;
      withBoundaryVariant(factors, [&](auto retain, auto conduct) {
        constexpr bool kRetain = decltype(retain)::value, kConduct = decltype(conduct)::value;
        for (int z = zs.begin(); z < zs.end(); ++z) {
          if (isotropic)
            gatherSliceIsotropic<kRetain, kConduct>(z, factors, field, next, accumulated, sums[z]);
          else
            gatherSlice<kRetain, kConduct>(z, factors, field, next, accumulated, sums[z]);
        }
      });
    });
    if (!isotropic && keepsIsotropic) {
      // The full step wrote zero linear planes into `next`; the isotropic steps leave
      // them as they are, so both buffers must hold zeros from here on.
      for (int ch = 0; ch < 3; ++ch)
        for (int k = 1; k < 4; ++k) std::fill(field.planes[ch * 4 + k].begin(), field.planes[ch * 4 + k].end(), 0.0f);
      isotropic = true;
    }
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
    if (options.chebyshev && options.autoSteps && keepsIsotropic) {
      // The first step has turned the injected light into y, isotropic and accumulated;
      // the rest of the lattice's light is (I - T)^-1 y - y.
      runChebyshev(factors, field, accumulated, options, maxSteps, result);
      break;
    }
    if (options.autoSteps) {
      const AutoStepDecision decision =
          decideAutoStop(total.inGrid, previousInGrid, accumulatedPower, options.autoTolerance, options.autoTailTolerance);
      previousInGrid = total.inGrid;
      if (decision.stop) {
        addTail(field, decision.tailScale, accumulated);
        result.tailScale = decision.tailScale;
        break;
      }
      result.capped = result.stepsRun >= maxSteps;
    }
  }
  return result;
}

}  // namespace sslpv

// Calibrated SSLPV transport; the model and its reasons are in docs/design.md §6.7
// "Calibrated scheme"; the closed form below is its §6.7.4.
//
// Derivation of the lattice's shaded reflectance R_lpv (semi-infinite layer stack n = 1,
// 2, ..., layer 0 outside; light injected isotropically, split between layers m and m + 1
// with weights 1 - f and f):
//  - every step moves 1/6 of a cell's power up, 1/6 down and 4/6 within the layer, times
//    s; of what layer 1 sends up, the boundary returns the share ρ into layer 1. The
//    power w(n) accumulated in layer n (the injected light included) solves
//      a w(n) - b (w(n-1) + w(n+1)) = q(n),  a = 1 - 4s/6,  b = s/6,  w(0) = ρ w(1),
//    with q the injected power. Its solutions are r^n and r^-n, r + 1/r = a/b = 6/s - 4;
//    u(n) = r^-n + β r^n, β = (ρ/r - 1) / (1 - ρ r), meets the boundary condition and
//    r^n decays, and their discrete Wronskian is b (1/r - r), so
//      G(1, m) = u(1) r^m / (b (1/r - r)) = 6 r^m / (s (1 - ρ r))
//    (u(1) = (1/r - r) / (1 - ρ r)), finite also at r -> 1. So
//      w(1) = 6 ((1 - f) r^m + f r^(m+1)) / (s (1 - ρ r)).
//  - the shading turns an isotropic cell of power P into radiance P / (2 π Δx²); with
//    irradiance E the injected power per cell is E Δx², so π L / E = w(1) / 2.
//  - with a boundary of relative index η the injection has already multiplied E by
//    1 - F(0) and the shading multiplies the radiance by (1 - F(θ)) / η², so the power the
//    lattice reflects is exitGain · R_lpv · (1 - F(0)) · T, T = 2 ∫ (1 - F(θ)) cos θ dcos θ / η²
//    over the outside hemisphere (diffuseBoundaryTransmittance: the share of an isotropic
//    field inside that crosses the boundary).
#include "volume/calibration/lpv_calibration.h"

#include "volume/calibration/exit_law.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "volume/calibration/adding_doubling.h"
#include "volume/core/fresnel.h"

namespace sslpv {
namespace {

constexpr int kReflectanceTable = 128;  // intervals over t = sqrt(1 - albedo) in [0, 1]

/// boundaryReflectance for one ior: Rd / albedo at t = i / kReflectanceTable. Dividing by
/// the albedo keeps the relative interpolation error small at low albedo, where Rd -> 0 as
/// fast as the albedo (single scattering).
struct BoundaryTable {
  double ior = 1.0;
  std::vector<double> rdOverAlbedo;
  double entering = 1.0;  ///< 1 - F(0): the injection's share of normal irradiance
  double leaving = 1.0;   ///< diffuseBoundaryTransmittance(ior): the shading's exit share
  double extrapolation = 2.0 / 3.0;  ///< z_b σt' = 2 A / 3 (diffusionBoundaryCoefficient)
  /// Per oblique node k = 1 .. kObliqueIntervals (y = 1 - k / kObliqueIntervals), over
  /// t = i / kObliqueAlbedoIntervals: the medium's diffuse reflectance per entering power
  /// at that incidence relative to normal incidence.
  std::array<std::vector<double>, kObliqueIntervals> obliqueRatio;
  /// singleScatteringPerEntering / albedo: at normal incidence, and per oblique node.
  double singleNormal = 0.0;
  std::array<double, kObliqueIntervals> singleOblique{};
  double secondScattering = 1.0;  ///< secondScatteringDepth(ior)
};

/// The oblique ratio varies slowly with the albedo, so 32 intervals (cubic) reproduce
/// adding-doubling to 1e-4, 3e-3 below α' = 0.1 where the share left after single
/// scattering bends fastest (lpv_calibration_test); the whole table takes ~38 ms per ior.
constexpr int kObliqueAlbedoIntervals = 32;

/// cos² θi at which a node is evaluated: the grazing node (y = 0) lets no power in, so it
/// holds the value at cos θi = 0.03; for η < 1, light arriving flatter than the critical
/// angle outside is totally reflected, so such nodes hold the flattest that enters.
double obliqueNodeCosineSquared(int k, double ior) {
  constexpr double kGrazing = 0.03 * 0.03;
  const double y = 1.0 - double(k) / kObliqueIntervals;
  return std::max({y, kGrazing, 1.0 - ior * ior + kGrazing});
}

/// cos θt inside for light arriving at cos² θi = y outside.
double refractedCosine(double y, double ior) { return std::sqrt(std::max(0.0, 1.0 - (1.0 - y) / (ior * ior))); }

/// The depth a beam at oblique node k (1 .. kObliqueIntervals) is injected at.
double obliqueNodeDepth(double injectionDepth, double ior, int k) {
  return injectionDepth * refractedCosine(obliqueNodeCosineSquared(k, ior), ior);
}

/// Diffusely reflected power per entering power of a beam entering at cos² θi = y, less
/// the once-scattered share the shading adds itself (singleScatteringPerEntering).
double reflectancePerEntering(double albedo, double ior, double y) {
  AddingDoublingOptions options;
  options.beamCosine = refractedCosine(y, ior);
  return addingDoublingHalfSpace(albedo, ior, options).rd / (1.0 - fresnelReflectance(std::sqrt(y), ior)) -
         singleScatteringPerEntering(albedo, ior, options.beamCosine);
}

std::unique_ptr<const BoundaryTable> buildBoundaryTable(double ior) {
  auto table = std::make_unique<BoundaryTable>();
  table->ior = ior;
  table->rdOverAlbedo.resize(kReflectanceTable + 1);
  for (int i = 0; i <= kReflectanceTable; ++i) {
    const double t = double(i) / kReflectanceTable;
    // t = 0: a non-absorbing half-space returns all the light that enters it (the solver
    // gets there only as 1/thickness). t = 1: the albedo -> 0 limit of Rd / albedo, which
    // Rd at albedo 1e-9 gives to a relative 1e-9.
    const double albedo = i == 0 ? 1.0 : std::max(1e-9, 1.0 - t * t);
    table->rdOverAlbedo[std::size_t(i)] =
        i == 0 ? 1.0 - fresnelReflectance(1.0, ior) : addingDoublingHalfSpace(albedo, ior).rd / albedo;
  }
  table->entering = 1.0 - fresnelReflectance(1.0, ior);
  table->singleNormal = singleScatteringPerEntering(1.0, ior, 1.0);
  table->secondScattering = secondScatteringDepth(ior);
  for (int k = 1; k <= kObliqueIntervals; ++k)
    table->singleOblique[std::size_t(k - 1)] =
        singleScatteringPerEntering(1.0, ior, refractedCosine(obliqueNodeCosineSquared(k, ior), ior));
  // Without its once-scattered light the share left is ∝ α'² as α' -> 0, and its ratio
  // tends to a limit (twice-scattered light's) that α' = 1e-3 gives to ~1e-3.
  const auto obliqueAlbedo = [](int i) {
    const double t = double(i) / kObliqueAlbedoIntervals;
    return std::max(1e-3, 1.0 - t * t);
  };
  std::vector<double> normal(kObliqueAlbedoIntervals + 1);
  for (int i = 1; i <= kObliqueAlbedoIntervals; ++i)
    normal[std::size_t(i)] = reflectancePerEntering(obliqueAlbedo(i), ior, 1.0);
  for (int k = 1; k <= kObliqueIntervals; ++k) {
    std::vector<double>& ratio = table->obliqueRatio[std::size_t(k - 1)];
    ratio.resize(kObliqueAlbedoIntervals + 1);
    const double y = obliqueNodeCosineSquared(k, ior);
    // t = 0: a non-absorbing half-space returns all that enters, at any angle.
    ratio[0] = (1.0 - table->singleOblique[std::size_t(k - 1)]) / (1.0 - table->singleNormal);
    for (int i = 1; i <= kObliqueAlbedoIntervals; ++i)
      ratio[std::size_t(i)] = reflectancePerEntering(obliqueAlbedo(i), ior, y) / normal[std::size_t(i)];
  }
  table->leaving = diffuseBoundaryTransmittance(ior);
  table->extrapolation = 2.0 * diffusionBoundaryCoefficient(ior) / 3.0;
  return table;
}

/// Built once per ior on first use, kept for the process (a scene has one ior; the editor
/// a few). The thread-local pointer skips the lock for the per-cell calls.
const BoundaryTable& boundaryTable(double ior) {
  thread_local const BoundaryTable* last = nullptr;
  if (last != nullptr && last->ior == ior) return *last;
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("boundaryReflectance: ior must be positive");
  static std::mutex mutex;
  static std::map<double, std::unique_ptr<const BoundaryTable>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<const BoundaryTable>& slot = tables[ior];
  if (!slot) slot = buildBoundaryTable(ior);
  last = slot.get();
  return *last;
}

/// Cubic interpolation through the 4 nearest of table[0..intervals] at t in [0, 1].
double interpolateCubic(const std::vector<double>& table, double t) {
  const int intervals = int(table.size()) - 1;
  t *= intervals;
  const int first = std::clamp(int(t) - 1, 0, intervals - 3);
  const double x = t - first;
  const double weights[4] = {-(x - 1.0) * (x - 2.0) * (x - 3.0) / 6.0, x * (x - 2.0) * (x - 3.0) / 2.0,
                             -x * (x - 1.0) * (x - 3.0) / 2.0, x * (x - 1.0) * (x - 2.0) / 6.0};
  double value = 0.0;
  for (int k = 0; k < 4; ++k) value += weights[k] * table[std::size_t(first + k)];
  return value;
}

/// The root of albedo · atanh(k) / k = 1 by bisection (the left side grows with k).
double solveAsymptoticDecay(double albedo) {
  if (albedo >= 1.0) return 0.0;
  if (albedo <= 0.0) return 1.0;
  double low = 0.0, high = 1.0;
  for (int i = 0; i < 200 && high - low > 1e-15; ++i) {
    const double k = 0.5 * (low + high);
    (albedo * std::atanh(k) / k > 1.0 ? high : low) = k;
  }
  return 0.5 * (low + high);
}

}  // namespace

double asymptoticDecay(double albedo) {
  // Over t = sqrt(1 - albedo) the root is smooth (k ≈ sqrt(3) t near albedo 1, -> 1 as
  // albedo -> 0), as the reflectance table's Rd / albedo is.
  static const std::vector<double> table = [] {
    std::vector<double> values(kReflectanceTable + 1);
    for (int i = 0; i <= kReflectanceTable; ++i) {
      const double t = double(i) / kReflectanceTable;
      values[std::size_t(i)] = solveAsymptoticDecay(1.0 - t * t);
    }
    return values;
  }();
  albedo = std::clamp(albedo, 0.0, 1.0);
  return std::clamp(interpolateCubic(table, std::sqrt(1.0 - albedo)), 0.0, 1.0);
}

double boundaryRetention(double extrapolationLength, double cellSize) {
  const double k = 2.0 * extrapolationLength / cellSize;
  if (!(k >= 0.0)) return kMinRetention;
  if (std::isinf(k)) return kMaxRetention;
  return std::clamp((k - 1.0) / (k + 1.0), kMinRetention, kMaxRetention);
}

bool parseLpvScheme(std::string_view name, LpvScheme& scheme) {
  if (name == "seed") {
    scheme = LpvScheme::Seed;
    return true;
  }
  if (name == "calibrated") {
    scheme = LpvScheme::Calibrated;
    return true;
  }
  return false;
}

std::string lpvSchemeName(LpvScheme scheme) { return scheme == LpvScheme::Seed ? "seed" : "calibrated"; }

double boundaryReflectance(double albedo, double ior) {
  const std::vector<double>& table = boundaryTable(ior).rdOverAlbedo;
  albedo = std::clamp(albedo, 0.0, 1.0);
  // Cubic: linear interpolation would be off by up to 4e-4 relative near albedo 1 at
  // η = 1.5, where Rd / albedo bends fastest in t.
  return albedo * interpolateCubic(table, std::sqrt(1.0 - albedo));
}

double halfSpaceReflectance(double albedo) { return boundaryReflectance(albedo, 1.0); }

double singleScatteringPerEntering(double albedo, double ior, double beamCosine) {
  // (α'/2) ∫ T(μ) μ / (μ + μt) dμ over the inside directions that leave (μ above the
  // critical cosine). T rises as sqrt(μ − μc) there, so Gauss-Legendre runs in t with
  // μ = μc + (1 − μc) t², dμ = 2 (1 − μc) t dt, where the integrand is smooth.
  const double muC = ior > 1.0 ? std::sqrt(1.0 - 1.0 / (ior * ior)) : 0.0;
  static const std::array<double, 8> x = {0.0950125098, 0.2816035508, 0.4580167777, 0.6178762444,
                                          0.7554044084, 0.8656312024, 0.9445750231, 0.9894009350};
  static const std::array<double, 8> w = {0.1894506105, 0.1826034150, 0.1691565194, 0.1495959888,
                                          0.1246289713, 0.0951585117, 0.0622535239, 0.0271524594};
  double sum = 0.0;
  for (int i = 0; i < 8; ++i)
    for (int sign = -1; sign <= 1; sign += 2) {
      const double t = 0.5 + 0.5 * sign * x[std::size_t(i)];
      const double mu = muC + (1.0 - muC) * t * t;
      sum += w[std::size_t(i)] * 0.5 * 2.0 * (1.0 - muC) * t * (1.0 - fresnelReflectanceFromInside(mu, ior)) * mu /
             (mu + beamCosine);
    }
  return 0.5 * std::clamp(albedo, 0.0, 1.0) * sum;
}

double incidentCosineSquared(double cosRefracted, double ior) {
  return std::clamp(1.0 - ior * ior * (1.0 - cosRefracted * cosRefracted), 0.0, 1.0);
}

double staircaseExitCorrection(double freshShare, double normalL1) {
  const double f = std::clamp(freshShare, 0.0, 1.0);
  return 1.0 / (1.0 - f + f / std::clamp(normalL1, 1.0, std::sqrt(3.0)));
}

namespace {

/// The shaded value of layers 1 and 2 (weights a and 1 - a) for an aligned face covering
/// `coverage` of its boundary cells, in all and of the light not yet propagated, up to a
/// factor common to every coverage (the derivation at the top of this file, with
/// G(n, m) = u(min) r^max / (b (1/r - r)) written as r^|n-m| + β r^(n+m) over 1 - r so
/// that it stays finite as s -> 1).
struct ShadedValue {
  double total = 0.0, fresh = 0.0;
};
ShadedValue alignedFaceShadedValue(double s, double zb, double z0, double dx, double c) {
  const double a4 = 6.0 / s - 4.0;
  const double r = a4 > 2.0 ? 2.0 / (a4 + std::sqrt(a4 * a4 - 4.0)) : 1.0;
  // The centre is (c - 1/2) Δx deep, so the profile's zero is zb + (c - 1/2) Δx from it:
  // the aligned rule at that distance less Δx / 2 (as boundaryRetentionFromSurface).
  const double rho = boundaryRetention(zb + (c - 1.0) * dx, dx);
  // r^k by multiplication: k is a few layers, and this runs for every boundary cell.
  const auto power = [r](int k) {
    double p = 1.0;
    for (int j = 0; j < k; ++j) p *= r;
    return p;
  };
  const auto green = [&](int n, int m) {
    if (1.0 - r < 1e-7) return 2.0 * (std::min(n, m) + rho / (1.0 - rho));  // the r -> 1 limit
    // β r^(n+m), β = (ρ/r - 1) / (1 - ρ r), without dividing by r.
    const double below = power(n + m - 1);
    const double reflected = (rho * below - below * r) / (1.0 - rho * r);
    return (power(std::abs(n - m)) + reflected) / (1.0 - r);
  };
  // The injection point max(z0, Δx/2) below the face, between the layers' centres at
  // (c - 1/2) Δx, (c + 1/2) Δx, ...; its weights are trilinear times coverage.
  const double layer = std::max(z0, 0.5 * dx) / dx + 1.5 - c;
  int deep = 1;
  double nearShare = 1.0;
  if (layer > 1.0) {
    deep = int(std::floor(layer));
    const double f = layer - deep;
    const double nearWeight = (1.0 - f) * (deep == 1 ? c : 1.0);
    nearShare = nearWeight / (nearWeight + f);
  }
  const auto held = [&](int n) { return nearShare * green(n, deep) + (1.0 - nearShare) * green(n, deep + 1); };
  const auto injected = [&](int n) { return (n == deep ? nearShare : 0.0) + (n == deep + 1 ? 1.0 - nearShare : 0.0); };
  // The shading reads Δx/2 below the face: trilinear weights c and 1 - c times coverage.
  const double first = c * c / (c * c + 1.0 - c);
  ShadedValue v;
  // green is G s (1 + r) / (6 r): the held light in units of the injected power.
  v.total = (first * held(1) + (1.0 - first) * held(2)) * 6.0 * r / (s * (1.0 + r));
  v.fresh = first * injected(1) + (1.0 - first) * injected(2);
  return v;
}

}  // namespace

double gridPhaseFreshGain(double survival, double extrapolationLength, double injectionDepth, double cellSize,
                          double coverage) {
  if (!(survival > 0.0) || !(cellSize > 0.0) || !(coverage > 0.0) || coverage >= 1.0) return 1.0;
  const double s = std::min(survival, 1.0);
  const ShadedValue aligned = alignedFaceShadedValue(s, extrapolationLength, injectionDepth, cellSize, 1.0);
  const ShadedValue phased = alignedFaceShadedValue(s, extrapolationLength, injectionDepth, cellSize, coverage);
  if (!(phased.fresh > 0.0)) return 1.0;
  const double gain = 1.0 + (aligned.total - phased.total) / phased.fresh;
  return std::isfinite(gain) ? std::clamp(gain, 0.0, kMaxFreshGain) : 1.0;
}


std::array<double, kObliqueIntervals> alignedPhaseObliqueFactors(double survival, double extrapolationLength,
                                                                 double injectionDepth, double cellSize, double ior,
                                                                 double coverage, double freshGain) {
  std::array<double, kObliqueIntervals> factors;
  factors.fill(1.0);
  if (!(survival > 0.0) || !(cellSize > 0.0) || !(injectionDepth > 0.0) || !(coverage > 0.0) || coverage >= 1.0)
    return factors;
  const double s = std::min(survival, 1.0);
  for (int k = 1; k <= kObliqueIntervals; ++k) {
    const double depth = obliqueNodeDepth(injectionDepth, ior, k);
    const ShadedValue phased = alignedFaceShadedValue(s, extrapolationLength, depth, cellSize, coverage);
    const double onBoundary = alignedFaceShadedValue(s, extrapolationLength, depth, cellSize, 1.0).total;
    const double factor = onBoundary / (phased.total + (freshGain - 1.0) * phased.fresh);
    if (std::isfinite(factor) && factor > 0.0) factors[std::size_t(k - 1)] = factor;
  }
  return factors;
}

std::array<double, kObliqueIntervals> tiltedPhaseObliqueFactors(double survival, double extrapolationLength,
                                                                double injectionDepth, double cellSize, double ior) {
  std::array<double, kObliqueIntervals> factors;
  factors.fill(1.0);
  if (!(survival > 0.0) || !(cellSize > 0.0) || !(injectionDepth > 0.0)) return factors;
  const double s = std::min(survival, 1.0);
  // A tilted face's cells take every phase along it: 8 midpoints of the coverage (16 move
  // the factors by under 0.2 %).
  constexpr int kPhases = 8;
  const auto phaseAverage = [&](double depth) {
    double sum = 0.0;
    for (int j = 0; j < kPhases; ++j)
      sum += alignedFaceShadedValue(s, extrapolationLength, depth, cellSize, (j + 0.5) / kPhases).total;
    return sum / kPhases / alignedFaceShadedValue(s, extrapolationLength, depth, cellSize, 1.0).total;
  };
  const double normal = phaseAverage(injectionDepth);
  for (int k = 1; k <= kObliqueIntervals; ++k) {
    const double factor = normal / phaseAverage(obliqueNodeDepth(injectionDepth, ior, k));
    if (std::isfinite(factor) && factor > 0.0) factors[std::size_t(k - 1)] = factor;
  }
  return factors;
}

double obliqueEntryGain(const float* nodes, double y) {
  // Node k sits at y = 1 - k / kObliqueIntervals; y = 1 (k = 0) has gain 1.
  const double x = std::clamp((1.0 - y) * kObliqueIntervals, 0.0, double(kObliqueIntervals));
  const int k = std::min(int(x), kObliqueIntervals - 1);
  const double below = k == 0 ? 1.0 : double(nodes[k - 1]), above = double(nodes[k]);
  return below + (x - k) * (above - below);
}

CellTransport seedTransport(double sigmaT, double sigmaS, double g, double cellSize) {
  const double e = std::exp(-sigmaT * cellSize);
  // Albedo of an empty cell is irrelevant (e = 1); guard the 0/0.
  const double albedo = sigmaT > 0.0 ? std::min(1.0, sigmaS / sigmaT) : 1.0;
  const double scattered = albedo * (1.0 - e);
  CellTransport t;
  t.dc = float(e + scattered);
  t.linear = float(e + scattered * g);
  t.obliqueGain.fill(1.0f);
  return t;
}

double secondScatteringDepth(double ior) {
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("secondScatteringDepth: ior must be positive");
  // First scattering at depth z ~ e^-z (mean free paths), a flight of length l ~ e^-l at
  // cosine μ to the inward normal, uniform in [-1, 1]. Downward (μ > 0) it scatters again
  // at z + μ l; upward (μ = -ν) at z − ν l when ν l < z, else it meets the boundary, which
  // reflects R(ν) of it to scatter at ν l − z (the rest leaves: single scattering). Over l:
  // downward E = z + μ; upward, staying: z (1 − e^-a) − ν (1 − e^-a (1 + a)), a = z / ν,
  // with weight 1 − e^-a; reflected: ν e^-a, weight e^-a. Midpoints in u = 1 − e^-z and ν.
  constexpr int kDepths = 400, kCosines = 400;
  double depthSum = 0.0, weightSum = 0.0;
  for (int i = 0; i < kDepths; ++i) {
    const double z = -std::log1p(-(i + 0.5) / kDepths);  // e^-z dz = du
    double depth = 0.5 * (z + 0.5), weight = 0.5;           // downward half
    for (int j = 0; j < kCosines; ++j) {
      const double nu = (j + 0.5) / kCosines, a = z / nu, e = std::exp(-a);
      const double reflected = fresnelReflectanceFromInside(nu, ior);
      depth += 0.5 / kCosines * (z * (1.0 - e) - nu * (1.0 - e * (1.0 + a)) + reflected * nu * e);
      weight += 0.5 / kCosines * (1.0 - e + reflected * e);
    }
    depthSum += depth;
    weightSum += weight;
  }
  return depthSum / weightSum;
}

CellTransport calibratedTransport(double sigmaT, double sigmaS, double g, double cellSize, double ior) {
  const double sigmaA = std::max(0.0, sigmaT - sigmaS);
  const double reducedS = std::max(0.0, sigmaS) * (1.0 - g);
  const double reducedT = sigmaA + reducedS;
  const double reducedAlbedo = reducedT > 0.0 ? reducedS / reducedT : 1.0;
  const double kappa = asymptoticDecay(reducedAlbedo) * reducedT * cellSize;
  // cosh overflows far beyond any useful κ; such a cell absorbs everything in one step.
  const double survival = kappa < 700.0 ? 3.0 / (2.0 + std::cosh(kappa)) : 0.0;
  const double r = std::exp(-kappa);
  const BoundaryTable& boundary = boundaryTable(ior);
  // An empty cell (σt' = 0) has infinite z0 and z_b: it keeps what it is sent and the
  // injection stays at its floor.
  const double retention =
      reducedT > 0.0 ? boundaryRetention(boundary.extrapolation / reducedT, cellSize) : kMaxRetention;
  const double firstScatterDepth = reducedT > 0.0 ? 1.0 / reducedT : 0.0;
  // R_lpv of light injected `depth` deep (the derivation at the top of this file).
  const auto layerOf = [&](double depth) { return std::max(depth, 0.5 * cellSize) / cellSize + 0.5; };
  const auto latticeReflectanceAt = [&](double depth) {
    if (!(survival > 0.0)) return 0.0;
    const double layer = layerOf(depth);
    const double first = std::floor(layer), deeper = layer - first;
    return 3.0 * std::pow(r, first) * (1.0 - deeper + deeper * r) / (survival * (1.0 - retention * r));
  };
  // The injection has already taken 1 - F(0) of the irradiance and the shading lets out
  // `leaving` of an isotropic cell's power, so this gain makes the lattice reflect the
  // medium's Rd less the once-scattered light the shading adds itself (single_scattering.h).
  const double target = (boundaryReflectance(reducedAlbedo, ior) / boundary.entering -
                         boundary.singleNormal * std::clamp(reducedAlbedo, 0.0, 1.0)) /
                        boundary.leaving;
  // The lattice's light has scattered at least twice: it starts where the second
  // scattering happens on average.
  const double injectionDepth = boundary.secondScattering * firstScatterDepth;
  const double latticeReflectance = latticeReflectanceAt(injectionDepth);
  double gain = latticeReflectance > 0.0 ? target / latticeReflectance : 0.0;
  if (!std::isfinite(gain) || reducedAlbedo <= 0.0) gain = 0.0;
  CellTransport t;
  t.dc = float(survival);
  t.linear = 0.0f;
  t.exitGain = float(gain);
  t.reducedAlbedo = float(reducedAlbedo);
  t.retention = float(retention);
  t.extrapolationLength =
      reducedT > 0.0 ? float(boundary.extrapolation / reducedT) : std::numeric_limits<float>::infinity();
  t.injectionDepth = float(injectionDepth);
  // The light injected into layer 1 (the floor, m* = 1) against all that layer holds.
  if (survival > 0.0) {
    const double layer = layerOf(injectionDepth);
    const double injectedInFirst = std::floor(layer) == 1.0 ? 2.0 - layer : 0.0;
    const double heldInFirst = 2.0 * latticeReflectance;  // w(1) = 2 R_lpv
    t.freshShare = heldInFirst > 0.0 ? float(std::min(1.0, injectedInFirst / heldInFirst)) : 0.0f;
  }
  const double t01 = std::sqrt(1.0 - std::clamp(reducedAlbedo, 0.0, 1.0));
  for (int k = 1; k <= kObliqueIntervals; ++k) {
    const double medium = interpolateCubic(boundary.obliqueRatio[std::size_t(k - 1)], t01);
    const double lattice = latticeReflectanceAt(obliqueNodeDepth(injectionDepth, ior, k));
    double nodeGain = lattice > 0.0 ? medium * latticeReflectance / lattice : 1.0;
    if (!std::isfinite(nodeGain) || !(nodeGain > 0.0)) nodeGain = 1.0;
    t.obliqueGain[std::size_t(k - 1)] = float(nodeGain);
  }
  return t;
}

void prepareCalibrationTables(double ior) {
  boundaryReflectance(1.0, ior);
  exitLawTable(ior);
}

}  // namespace sslpv

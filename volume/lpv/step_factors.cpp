// Per-cell step factors: the propagation's per-step band factors, and in the calibrated
// scheme the exit gains, boundary retentions and injection depths the surface needs
// (docs/design.md §6.7.3 for the staircase and grid-phase rules, §6.7.4 for the exit-gain
// limit, §6.7.7 for the conductances).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include "volume/lpv/lpv_stages.h"

namespace sslpv {
namespace {
// The calibrated exit gain maps a homogeneous medium's lattice reflectance to the true
// one. It is calibrated for light injected in the cell's own material: it is larger where
// that light sits near the surface cell with little retention (dense cells, injected at
// the Δx / 2 floor) than where it is injected deep behind a retaining boundary (thin
// bright media at fine cells). A dense spot painted into a thin bright medium also
// receives light diffusing in from its surroundings, and its larger gain would turn that
// into a glow. So a cell uses the smallest gain among itself and the cells up to
// kExitGainReach cells away along the axes whose reduced albedo (this channel) is at
// least its own: the media its light can have come from in quantity. Inside a
// homogeneous region nothing changes (all gains equal); a brighter cell never takes a
// darker neighbour's gain (no fringes between painted media). (With the seed-style
// cosine-lobe injection any absorbing spot had this problem; with the isotropic
// injection at depth an absorbing spot's own gain is the smaller one.)
constexpr int kExitGainReach = 2;

void limitExitGainToNeighbours(const MaterialGrid& material, StepFactors& factors) {
  const GridFrame& f = material.frame;
  const std::size_t n = f.cellCount();
  for (int ch = 0; ch < 3; ++ch) {
    std::vector<float> albedo(n, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
      if (!factors.active[i]) continue;
      const double g = material.g[i], sigmaS = material.sigmaS[i][ch], sigmaT = material.sigmaT[i][ch];
      const double reducedT = sigmaT - sigmaS * g;
      albedo[i] = reducedT > 0.0 ? float(sigmaS * (1.0 - g) / reducedT) : 0.0f;
    }
    const std::vector<float> own = factors.exitGain[ch];
    tbb::parallel_for(0, f.dims.z, [&](int z) {
      for (int y = 0; y < f.dims.y; ++y)
        for (int x = 0; x < f.dims.x; ++x) {
          const std::size_t i = f.index(x, y, z);
          if (!factors.active[i]) continue;
          float smallest = own[i];
          for (int axis = 0; axis < 3; ++axis)
            for (int d = -kExitGainReach; d <= kExitGainReach; ++d) {
              glm::ivec3 other(x, y, z);
              other[axis] += d;
              if (d == 0 || other[axis] < 0 || other[axis] >= f.dims[axis]) continue;
              const std::size_t j = f.index(other.x, other.y, other.z);
              if (factors.active[j] && albedo[j] >= albedo[i]) smallest = std::min(smallest, own[j]);
            }
          factors.exitGain[ch][i] = smallest;
        }
    });
  }
}

/// The coverage gradient over a cell's 3x3x3 neighbourhood (its direction points into the
/// object): over a staircase of partly covered cells it follows the surface's plane rather
/// than the axis of the nearest step. Active cells never touch the grid's edge, so the
/// neighbours exist.
glm::dvec3 coverageGradient(const MaterialGrid& material, int x, int y, int z) {
  const GridFrame& f = material.frame;
  glm::dvec3 gradient(0.0);
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        gradient += double(material.coverage[f.index(x + dx, y + dy, z + dz)]) * glm::dvec3(dx, dy, dz);
  return gradient;
}

/// Calls visit(cell index, x, y, z, unit normal into the object) for every active cell
/// with a coverage gradient (on or next to the surface), in parallel over slices.
template <class Visit>
void forEachSurfaceCell(const MaterialGrid& material, const StepFactors& factors, Visit&& visit) {
  const GridFrame& f = material.frame;
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (!factors.active[i]) continue;
        const glm::dvec3 gradient = coverageGradient(material, x, y, z);
        const double length = glm::length(gradient);
        if (!(length > 1e-6)) continue;
        visit(i, x, y, z, gradient / length);
      }
  });
}

/// Multiplies each boundary cell's exit gain by staircaseExitCorrection for its surface
/// normal, the direction of coverageGradient. Cells with no coverage change around them
/// (interior, or an aligned face's flat side along which the gradient is axial) get
/// |n|_1 = 1 and keep their gain.
void correctStaircaseExit(const MaterialGrid& material, const std::array<std::vector<float>, 3>& freshShare,
                          StepFactors& factors) {
  forEachSurfaceCell(material, factors, [&](std::size_t i, int, int, int, const glm::dvec3& normal) {
    const double normalL1 = std::abs(normal.x) + std::abs(normal.y) + std::abs(normal.z);
    for (int ch = 0; ch < 3; ++ch)
      factors.exitGain[ch][i] *= float(staircaseExitCorrection(freshShare[ch][i], normalL1));
  });
}

/// Volume of the unit cube below the plane n·x = alpha, for n with positive components
/// (Scardovelli & Zaleski 2000): inclusion-exclusion over the corners the plane passes.
double cubeVolumeBelowPlane(const glm::dvec3& n, double alpha) {
  auto cube = [](double v) { return v > 0.0 ? v * v * v : 0.0; };
  const double volume = cube(alpha) - cube(alpha - n.x) - cube(alpha - n.y) - cube(alpha - n.z) +
                        cube(alpha - n.x - n.y) + cube(alpha - n.x - n.z) + cube(alpha - n.y - n.z) -
                        cube(alpha - n.x - n.y - n.z);
  return volume / (6.0 * n.x * n.y * n.z);
}

/// Depth of a cell's centre below a planar surface of unit normal n that leaves `coverage`
/// of the cell inside, in cells (1/2 when the surface is the cell's outer face).
double centreDepthBelowSurface(glm::dvec3 n, double coverage) {
  // Components of exactly 0 would divide by zero; 1e-3 moves the depth by under 1e-3.
  n = glm::max(glm::abs(n), glm::dvec3(1e-3));
  n /= glm::length(n);
  double low = 0.0, high = n.x + n.y + n.z;
  for (int i = 0; i < 50; ++i) {
    const double alpha = 0.5 * (low + high);
    (cubeVolumeBelowPlane(n, alpha) < coverage ? low : high) = alpha;
  }
  return 0.5 * (low + high) - 0.5 * (n.x + n.y + n.z);
}

/// Turns the extrapolation lengths into each active cell's boundary retention: the share
/// its outside (inactive) neighbours return, summed over them.
///
/// ρ = (k - 1) / (k + 1), k = 2 z_b / Δx (boundaryRetention) puts the linear profile's zero
/// z_b beyond an axis-aligned face, D = Δx / 2 + z_b from the boundary cell's centre; it is
/// 1 - Δx / D. A tilted surface is a staircase of cells whose centres sit at other depths
/// d below it, with |nx| + |ny| + |nz| outside faces per Δx² of surface (up to sqrt 3):
/// with the flat ρ on every face a 30° or 3D-diagonal face of a thick ketchup slab came out
/// x0.92 / x0.88 of the same slab axis-aligned, one of marble x1.10 / x1.15. Along axis a
/// the zero plane at D = d + z_b from the centre is D / |n_a| away, so each outside face
/// along a returns ρ_a = 1 - |n_a| Δx / D: the same zero along every axis. n comes from the
/// coverage gradient over the cell's 3x3x3 neighbourhood and d from the cell's own coverage
/// cut by a plane of that normal.
void boundaryRetentionFromSurface(const MaterialGrid& material, const std::array<std::vector<float>, 3>& extrapolation,
                                  StepFactors& factors) {
  const GridFrame& f = material.frame;
  const double dx = f.cellSize;
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (!factors.active[i]) continue;
        glm::ivec3 outsideAlong(0);  // outside neighbours per axis
        for (int axis = 0; axis < 3; ++axis)
          for (int d = -1; d <= 1; d += 2) {
            glm::ivec3 other(x, y, z);
            other[axis] += d;
            // Active cells never touch the grid's edge (the outer ring is inactive).
            if (!factors.active[f.index(other.x, other.y, other.z)]) ++outsideAlong[axis];
          }
        for (int ch = 0; ch < 3; ++ch) factors.retention[ch][i] = 0.0f;
        if (outsideAlong == glm::ivec3(0)) continue;
        const glm::dvec3 gradient = coverageGradient(material, x, y, z);
        // No gradient (a cell alone or in a one-cell sliver): the faces it has outside.
        const glm::dvec3 normal = glm::length(gradient) > 0.0 ? glm::abs(glm::normalize(gradient))
                                                             : glm::normalize(glm::dvec3(outsideAlong));
        const double depth = centreDepthBelowSurface(normal, material.coverage[i]) * dx;
        for (int ch = 0; ch < 3; ++ch) {
          const double zb = extrapolation[ch][i];
          const double reach = depth + zb;
          double sum = 0.0;
          for (int axis = 0; axis < 3; ++axis) {
            if (outsideAlong[axis] == 0) continue;
            // Along the axis the profile's zero is reach / |n_a| from the centre, that
            // minus Δx / 2 beyond the face: the aligned rule at that distance. A centre
            // beyond the zero (reach <= 0, a barely covered cell of a dense medium) gets
            // a negative distance, so the face drains all it can (kMinRetention).
            sum += boundaryRetention(reach / normal[axis] - 0.5 * dx, dx) * outsideAlong[axis];
          }
          factors.retention[ch][i] = float(sum);
        }
      }
  });
}

/// Below the first of these angles between a face's normal and the nearest axis the face
/// counts as aligned (each cell corrected for its own coverage), above the second as
/// tilted (corrected for the phases averaged): over a face tilted by θ the boundary cell's
/// phase cycles every 1 / tan θ cells, and from 15° (under 4 cells) the shading's 2-cell
/// stencil already averages the phases.
constexpr double kPhaseAlignedDeg = 5.0, kPhaseTiltedDeg = 15.0;

/// Corrects for where the grid falls against the surface (lpv_calibration.h,
/// gridPhaseFreshGain and the phase oblique factors): without it an aligned face that falls
/// inside its cells read up to a third dark or 10 % bright depending on where the grid
/// happened to fall (ketchup_box's top at 32³: green and blue 0.85 of the path tracer),
/// and a tilted face lit obliquely 10-15 % dark in low-albedo channels.
///  - The boundary cell of an aligned face gets the fresh gain and oblique factors for its
///    coverage. The cell inward of it, which the shading also reads and which the
///    injection picks as the surface cell when the coverage is low, gets the same (the
///    mean, inside an edge where it lies inward of several).
///  - A cell on a tilted face gets the phase-averaged oblique factors; between 5° and 15°
///    from an axis the two blend.
void correctGridPhase(const MaterialGrid& material, const std::array<std::vector<float>, 3>& extrapolation,
                      StepFactors& factors) {
  const GridFrame& f = material.frame;
  const std::size_t n = f.cellCount();
  const double dx = f.cellSize;
  constexpr std::size_t kNone = ~std::size_t(0);
  // Per cell: its aligned weight (-1: no surface around it), whether it is an aligned
  // face's boundary cell, that face's coverage, and the boundary cell's inward neighbour.
  std::vector<float> alignedWeight(n, -1.0f), faceCoverage(n, 1.0f);
  std::vector<char> boundary(n, 0);
  std::vector<std::size_t> inner(n, kNone);
  forEachSurfaceCell(material, factors, [&](std::size_t i, int x, int y, int z, const glm::dvec3& normal) {
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(normal[a]) > std::abs(normal[axis])) axis = a;
    const double alignment = std::abs(normal[axis]);
    const double angle = std::acos(std::min(1.0, alignment)) * 180.0 / SSLPV_PI;
    const double weight = std::clamp((kPhaseTiltedDeg - angle) / (kPhaseTiltedDeg - kPhaseAlignedDeg), 0.0, 1.0);
    alignedWeight[i] = float(weight);
    const int inward = normal[axis] > 0.0 ? 1 : -1;
    glm::ivec3 outside(x, y, z), inside(x, y, z);
    outside[axis] -= inward;
    inside[axis] += inward;
    // Active cells never touch the grid's edge, so both neighbours exist.
    if (weight == 0.0 || factors.active[f.index(outside.x, outside.y, outside.z)]) return;
    boundary[i] = 1;
    const double centreDepth = centreDepthBelowSurface(glm::abs(normal), material.coverage[i]) / alignment;
    faceCoverage[i] = float(std::clamp(centreDepth + 0.5, 0.0, 1.0));
    const std::size_t j = f.index(inside.x, inside.y, inside.z);
    if (factors.active[j]) inner[i] = j;
  });
  // The inner cells' face coverage, serially: several boundary cells can share one.
  std::vector<float> innerCoverage(n, 0.0f);
  std::vector<int> innerCount(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = inner[i];
    if (j == kNone || boundary[j]) continue;
    ++innerCount[j];
    innerCoverage[j] += faceCoverage[i];
  }
  using ObliqueNodes = std::array<double, kObliqueIntervals>;
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    std::map<std::array<float, 3>, ObliqueNodes> tiltedByMedium;
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        const double weight = alignedWeight[i];
        if (weight < 0.0) continue;
        const double coverage = innerCount[i] > 0 ? innerCoverage[i] / innerCount[i] : faceCoverage[i];
        if (weight == 1.0 && coverage == 1.0) continue;  // no phase to correct
        for (int ch = 0; ch < 3; ++ch) {
          const double survival = factors.dc[ch][i], zb = extrapolation[ch][i], depth = factors.injectionDepth[ch][i];
          const double fresh = 1.0 + weight * (gridPhaseFreshGain(survival, zb, depth, dx, coverage) - 1.0);
          factors.freshGain[ch][i] = float(fresh);
          ObliqueNodes nodes;
          nodes.fill(0.0);
          if (weight < 1.0) {
            // Once per medium and slice.
            const std::array<float, 3> key{float(survival), float(zb), float(depth)};
            auto found = tiltedByMedium.find(key);
            if (found == tiltedByMedium.end())
              found = tiltedByMedium
                          .emplace(key, tiltedPhaseObliqueFactors(survival, zb, depth, dx, factors.ior))
                          .first;
            for (int k = 0; k < kObliqueIntervals; ++k) nodes[std::size_t(k)] = (1.0 - weight) * found->second[std::size_t(k)];
          }
          if (weight > 0.0) {
            const ObliqueNodes aligned =
                alignedPhaseObliqueFactors(survival, zb, depth, dx, factors.ior, coverage, fresh);
            for (int k = 0; k < kObliqueIntervals; ++k) nodes[std::size_t(k)] += weight * aligned[std::size_t(k)];
          }
          float* gain = &factors.obliqueGain[ch][i * std::size_t(kObliqueIntervals)];
          for (int k = 0; k < kObliqueIntervals; ++k) gain[k] *= float(nodes[std::size_t(k)]);
        }
      }
  });
}

/// The lattice carries light that has scattered at least twice, with gains derived for a
/// half-space, into which all entering light scatters and from which scattered light
/// scatters again before it can leave. In an object of optical thickness τ (its mean
/// chord in σt', similarity relation) a beam scatters at all with probability about
/// 1 - e^-τ, and its scattered light again about as likely: the lattice's light is scaled
/// by (1 - e^-τ)², 1 in thick objects. Without it an object 2e-5 mean free paths thick came
/// out ~10^4 times as bright as the path tracer (all its light was taken to diffuse).
void correctThinObject(const MaterialGrid& material, StepFactors& factors) {
  const std::size_t n = material.frame.cellCount();
  for (int ch = 0; ch < 3; ++ch) {
    double weighted = 0.0, weights = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!factors.active[i]) continue;
      const double reducedT = std::max(0.0, double(material.sigmaT[i][ch]) - double(material.sigmaS[i][ch]) * material.g[i]);
      const double tau = reducedT * material.meanChord;
      const double interacts = -std::expm1(-tau);
      factors.exitGain[ch][i] = float(double(factors.exitGain[ch][i]) * interacts * interacts);
      weighted += material.coverage[i] * reducedT;
      weights += material.coverage[i];
    }
    factors.opticalThickness[ch] = weights > 0.0 ? weighted / weights * material.meanChord : 0.0;
  }
}

/// The gain calibrated for a half-space of one material makes a path that enters and
/// leaves through that material right, whichever end carries it. Where the path enters
/// through one material and leaves through another, the exit-side gain alone gave it the
/// exit material's gain: a backlit slab under a thin absorbing layer came out at that
/// layer's gain over the core's (×0.16 in blue), and lit from the other side at the
/// inverse, while transport (and the lattice, whose propagation is symmetric) gives the
/// same light both ways round. Half the gain (its square root) goes to the entry, half
/// stays on the exit; the geometric corrections of the exit reading stay on the exit.
void splitGainBetweenEntryAndExit(const MaterialGrid& material, StepFactors& factors) {
  const std::size_t n = material.frame.cellCount();
  for (int ch = 0; ch < 3; ++ch)
    for (std::size_t i = 0; i < n; ++i) {
      const float coupling = factors.entryCoupling[ch][i];
      if (factors.active[i] && coupling > 0.0f) factors.exitGain[ch][i] /= coupling;
    }
}

}  // namespace

StepFactors computeStepFactors(const MaterialGrid& material, LpvScheme scheme, double ior) {
  const GridFrame& f = material.frame;
  const std::size_t n = f.cellCount();
  StepFactors factors;
  factors.scheme = scheme;
  factors.ior = ior;
  std::array<std::vector<float>, 3> extrapolation;  // z_b per channel and cell (calibrated)
  for (int ch = 0; ch < 3; ++ch) {
    factors.dc[ch].assign(n, 0.0f);
    factors.linear[ch].assign(n, 0.0f);
    factors.exitGain[ch].assign(n, 1.0f);
    if (scheme == LpvScheme::Calibrated) {
      factors.reducedAlbedo[ch].assign(n, 0.0f);
      factors.retention[ch].assign(n, 0.0f);
      extrapolation[ch].assign(n, 0.0f);
      factors.injectionDepth[ch].assign(n, 0.0f);
      factors.obliqueGain[ch].assign(n * kObliqueIntervals, 1.0f);
      factors.freshGain[ch].assign(n, 1.0f);
      factors.entryCoupling[ch].assign(n, 1.0f);
    }
  }
  factors.active.assign(n, 0);
  factors.rowActive.assign(std::size_t(f.dims.y) * f.dims.z, 0);
  const double dx = f.cellSize;
  std::array<std::vector<float>, 3> freshShare;
  if (scheme == LpvScheme::Calibrated)
    for (int ch = 0; ch < 3; ++ch) freshShare[ch].assign(n, 0.0f);
  tbb::parallel_for(0, f.dims.z, [&](int z) {
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (!isActiveCell(material, x, y, z)) continue;
        factors.active[i] = 1;
        factors.rowActive[std::size_t(z) * f.dims.y + y] = 1;
        for (int ch = 0; ch < 3; ++ch) {
          const double sigmaT = material.sigmaT[i][ch], sigmaS = material.sigmaS[i][ch];
          const CellTransport t = scheme == LpvScheme::Seed
                                      ? seedTransport(sigmaT, sigmaS, material.g[i], dx)
                                      : calibratedTransport(sigmaT, sigmaS, material.g[i], dx, ior);
          factors.dc[ch][i] = t.dc;
          factors.linear[ch][i] = t.linear;
          factors.exitGain[ch][i] = t.exitGain;
          if (scheme == LpvScheme::Calibrated) {
            factors.entryCoupling[ch][i] = std::sqrt(t.exitGain);
            factors.reducedAlbedo[ch][i] = t.reducedAlbedo;
            extrapolation[ch][i] = t.extrapolationLength;
            factors.injectionDepth[ch][i] = t.injectionDepth;
            freshShare[ch][i] = t.freshShare;
            std::copy(t.obliqueGain.begin(), t.obliqueGain.end(),
                      factors.obliqueGain[ch].begin() + std::ptrdiff_t(i * kObliqueIntervals));
          }
        }
      }
  });
  if (scheme == LpvScheme::Calibrated) {
    boundaryRetentionFromSurface(material, extrapolation, factors);
    limitExitGainToNeighbours(material, factors);
    correctStaircaseExit(material, freshShare, factors);
    correctGridPhase(material, extrapolation, factors);
    std::array<std::vector<float>, 3> conductance = diffusivityConductance(material, factors);
    if (!conductance[0].empty()) applyConductance(material, std::move(conductance), factors);
    if (material.meanChord > 0.0) correctThinObject(material, factors);
    splitGainBetweenEntryAndExit(material, factors);
  }
  return factors;
}

std::array<std::vector<float>, 3> diffusivityConductance(const MaterialGrid& material, const StepFactors& factors) {
  const std::size_t n = material.frame.cellCount();
  std::array<std::vector<float>, 3> conductance;
  bool uniform = true;
  for (int ch = 0; ch < 3; ++ch) {
    // The diffusion coefficient in units of 1/3: 1/σt' (an empty cell's is infinite).
    std::vector<double> diffusivity(n, 0.0);
    double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!factors.active[i]) continue;
      const double reducedT = double(material.sigmaT[i][ch]) - double(material.sigmaS[i][ch]) * material.g[i];
      diffusivity[i] = reducedT > 0.0 ? 1.0 / reducedT : std::numeric_limits<double>::infinity();
      smallest = std::min(smallest, diffusivity[i]);
      largest = std::max(largest, diffusivity[i]);
    }
    const double reference = std::min(largest, kMaxDiffusivityContrast * smallest);
    conductance[ch].assign(n, 1.0f);
    if (!(reference > 0.0) || !std::isfinite(smallest)) continue;
    for (std::size_t i = 0; i < n; ++i) {
      if (!factors.active[i]) continue;
      const float root = float(std::sqrt(std::min(1.0, diffusivity[i] / reference)));
      conductance[ch][i] = root;
      if (root < 1.0f) uniform = false;
    }
  }
  if (uniform)
    for (auto& c : conductance) c.clear();
  return conductance;
}

void applyConductance(const MaterialGrid& material, std::array<std::vector<float>, 3> conductance,
                      StepFactors& factors) {
  const GridFrame& f = material.frame;
  for (int ch = 0; ch < 3; ++ch) {
    const std::vector<float>& c = conductance[ch];
    tbb::parallel_for(0, f.dims.z, [&](int z) {
      for (int y = 0; y < f.dims.y; ++y)
        for (int x = 0; x < f.dims.x; ++x) {
          const std::size_t i = f.index(x, y, z);
          if (!factors.active[i]) continue;
          const double w = double(c[i]) * c[i];
          // What the cell keeps, in units of what an isotropic cell sends one neighbour:
          // the share each face no longer passes, plus the boundary's return, which
          // outside faces (conductance w, the cell's own) now apply to w of it.
          double hold = w * factors.retention[ch][i];
          for (int axis = 0; axis < 3; ++axis)
            for (int d = -1; d <= 1; d += 2) {
              glm::ivec3 other(x, y, z);
              other[axis] += d;
              // Active cells never touch the grid's edge, so the neighbour exists.
              const std::size_t j = f.index(other.x, other.y, other.z);
              hold += 1.0 - (factors.active[j] ? double(c[i]) * c[j] : w);
            }
          factors.retention[ch][i] = float(hold / w);
          const double survival = factors.dc[ch][i];
          if (!(survival > 0.0)) continue;  // absorbs everything in one step at any rate
          const double scale = 1.0 + survival * (1.0 / w - 1.0);  // λ
          factors.dc[ch][i] = float(1.0 / (1.0 + w * (1.0 / survival - 1.0)));
          factors.exitGain[ch][i] = float(factors.exitGain[ch][i] / scale);
          factors.freshGain[ch][i] = float(1.0 + scale * (factors.freshGain[ch][i] - 1.0));
        }
    });
  }
  factors.conductance = std::move(conductance);
}

bool keepsCellsIsotropic(const StepFactors& factors) {
  for (const std::vector<float>& channel : factors.linear)
    for (float l : channel)
      if (l != 0.0f) return false;
  return true;
}

void addInjected(const std::array<std::vector<float>, 3>& freshGain, const ShGrid& injected, ShGrid& accumulated) {
  for (int k = 0; k < ShGrid::kPlanes; ++k) {
    const std::vector<float>& from = injected.planes[k];
    std::vector<float>& to = accumulated.planes[k];
    const std::vector<float>& gain = freshGain[std::size_t(k / 4)];
    if (gain.empty())
      std::transform(to.begin(), to.end(), from.begin(), to.begin(), std::plus<float>());
    else
      for (std::size_t i = 0; i < to.size(); ++i) to[i] += gain[i] * from[i];
  }
}

}  // namespace sslpv

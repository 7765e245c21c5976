// The calibrated lattice's per-cell diffusion coefficient (docs/design.md §6.7.7):
// a homogeneous medium renders the same at any conductance, and light crossing an
// interface between media of different D divides as diffusion theory says, where the
// lattice with one D for every cell sends twice as much across.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "lpv_test_grids.h"
#include "volume/calibration/lpv_calibration.h"
#include "volume/cpu/propagate.h"

namespace {
using namespace sslpv;

PropagationOptions converged() {
  PropagationOptions options;
  options.autoSteps = true;
  options.autoTolerance = 1e-8;
  options.autoTailTolerance = 1e-7;
  options.maxAutoSteps = 100000;
  return options;
}

/// The accumulated DC of every cell times its exit gain: what shading reads, per channel.
std::vector<double> readBack(const StepFactors& factors, const ShGrid& accumulated, int ch) {
  std::vector<double> out(accumulated.planes[std::size_t(ch) * 4].size());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = double(accumulated.plane(ch, 0)[i]) * factors.exitGain[std::size_t(ch)][i];
  return out;
}

TEST(Diffusivity, UniformMediaNeedNoConductance) {
  const MaterialGrid m = test::uniformMaterial(8, glm::vec3(2.0f, 3.0f, 4.0f), glm::vec3(1.9f, 2.5f, 3.0f), 0.3f, 0.5);
  const StepFactors f = computeStepFactors(m, LpvScheme::Calibrated, 1.4);
  for (int ch = 0; ch < 3; ++ch) EXPECT_TRUE(f.conductance[std::size_t(ch)].empty());
  EXPECT_TRUE(computeStepFactors(m, LpvScheme::Seed, 1.4).conductance[0].empty());
}

TEST(Diffusivity, ConductanceFollowsReducedExtinctionUpToTheContrastCap) {
  // D = 1/(3σt'): a cell of a quarter the σt' has 4x the D, so the rest get w = 1/4; a
  // cell 20x thinner than the densest is beyond the cap and the densest gets 1/8.
  MaterialGrid m = test::uniformMaterial(7, glm::vec3(4.0f), glm::vec3(3.0f), 0.0f, 0.5);
  const std::size_t thin = m.frame.index(3, 3, 3), dense = m.frame.index(2, 3, 3);
  m.sigmaT[thin] = glm::vec3(1.0f, 0.2f, 4.0f);
  m.sigmaS[thin] = glm::vec3(0.75f, 0.15f, 3.0f);
  const auto c = diffusivityConductance(m, computeStepFactors(m, LpvScheme::Seed, 1.0));
  ASSERT_FALSE(c[0].empty());
  EXPECT_FLOAT_EQ(c[0][thin], 1.0f);
  EXPECT_FLOAT_EQ(c[0][dense] * c[0][dense], 0.25f);
  EXPECT_FLOAT_EQ(c[1][thin], 1.0f);
  EXPECT_FLOAT_EQ(c[1][dense] * c[1][dense], float(1.0 / kMaxDiffusivityContrast));
  EXPECT_FLOAT_EQ(c[2][dense], 1.0f);  // blue is uniform
}

TEST(Diffusivity, HomogeneousMediumReadsTheSameAtAnyConductance) {
  // Slowing every face to w = 0.3 holds light longer; with the survival, exit gain and
  // fresh gain rescaled (λ) the light read back is the same, boundary cells included.
  // Tolerance: both runs stop at 1e-8 of the accumulated power per step (tail estimated).
  const MaterialGrid m = test::uniformMaterial(12, glm::vec3(1.5f, 3.0f, 8.0f), glm::vec3(1.4f, 2.4f, 4.0f), 0.2f, 0.4);
  const StepFactors plain = computeStepFactors(m, LpvScheme::Calibrated, 1.4);
  ASSERT_TRUE(plain.conductance[0].empty());
  StepFactors slow = plain;
  std::array<std::vector<float>, 3> conductance;
  for (auto& c : conductance) c.assign(m.frame.cellCount(), float(std::sqrt(0.3)));
  applyConductance(m, conductance, slow);

  ShGrid injected;
  injected.resize(m.frame);
  for (int ch = 0; ch < 3; ++ch) {
    injected.plane(ch, 0)[m.frame.index(1, 5, 6)] = 1.0f;  // a boundary cell
    injected.plane(ch, 0)[m.frame.index(6, 6, 5)] = 0.5f;  // deep inside
  }
  ShGrid field = injected, plainLight, slowLight;
  plainLight.resize(m.frame);
  slowLight.resize(m.frame);
  const PropagationResult plainRun = propagate(m, plain, field, plainLight, converged());
  field = injected;
  const PropagationResult slowRun = propagate(m, slow, field, slowLight, converged());
  EXPECT_GT(slowRun.stepsRun, 2 * plainRun.stepsRun) << "w = 0.3 should need about 3x the steps";
  for (int ch = 0; ch < 3; ++ch) {
    const std::vector<double> a = readBack(plain, plainLight, ch), b = readBack(slow, slowLight, ch);
    const double peak = *std::max_element(a.begin(), a.end());
    for (std::size_t i = 0; i < a.size(); ++i)
      ASSERT_NEAR(b[i], a[i], 2e-4 * peak) << "cell " << i << " channel " << ch;
  }
}

/// A chain of cells along x (the only active row of an N x 3 x 3 grid) whose four lateral
/// faces reflect everything: the lattice's plane-wave geometry, as for an infinite slab
/// lit uniformly. Medium A up to cell `interface` - 1, medium B from it on.
struct Chain {
  MaterialGrid material;
  StepFactors factors;
  int interface = 0;
};

Chain makeChain(int cells, int interface, glm::vec3 sigmaTA, glm::vec3 sigmaSA, glm::vec3 sigmaTB,
                glm::vec3 sigmaSB, double cellSize, bool varyDiffusivity) {
  Chain chain;
  chain.interface = interface;
  MaterialGrid& m = chain.material;
  m.frame.cellSize = cellSize;
  m.frame.dims = glm::ivec3(cells, 3, 3);
  const std::size_t n = m.frame.cellCount();
  m.coverage.assign(n, 0.0f);
  m.sigmaT.assign(n, sigmaTA);
  m.sigmaS.assign(n, sigmaSA);
  m.g.assign(n, 0.0f);
  for (int x = 1; x < cells - 1; ++x) m.coverage[m.frame.index(x, 1, 1)] = 1.0f;
  for (int x = interface; x < cells; ++x) {
    m.sigmaT[m.frame.index(x, 1, 1)] = sigmaTB;
    m.sigmaS[m.frame.index(x, 1, 1)] = sigmaSB;
  }
  StepFactors& f = chain.factors;
  f = computeStepFactors(m, LpvScheme::Calibrated, 1.0);
  // Rebuild what each cell keeps for reflecting outside faces (ρ = 1: the face keeps all
  // it would send), with the chain's own conductances.
  const std::array<std::vector<float>, 3> conductance = diffusivityConductance(m, f);
  for (int ch = 0; ch < 3; ++ch)
    for (int x = 1; x < cells - 1; ++x) {
      const std::size_t i = m.frame.index(x, 1, 1);
      const double ci = conductance[0].empty() || !varyDiffusivity ? 1.0 : conductance[std::size_t(ch)][i];
      double hold = 4.0;  // the lateral faces
      for (int d = -1; d <= 1; d += 2) {
        const bool inside = x + d >= 1 && x + d <= cells - 2;
        const double cj = inside && varyDiffusivity ? conductance[std::size_t(ch)][i + std::size_t(d)] : ci;
        hold += inside ? 1.0 - ci * cj : 1.0;
      }
      f.retention[std::size_t(ch)][i] = float(hold / (ci * ci));
      f.dc[std::size_t(ch)][i] = calibratedTransport(m.sigmaT[i][ch], m.sigmaS[i][ch], 0.0, cellSize, 1.0).dc;
      if (varyDiffusivity) {
        const double w = ci * ci, s = f.dc[std::size_t(ch)][i];
        f.dc[std::size_t(ch)][i] = float(1.0 / (1.0 + w * (1.0 / s - 1.0)));
      }
    }
  for (auto& fresh : f.freshGain) std::fill(fresh.begin(), fresh.end(), 1.0f);
  if (varyDiffusivity) {
    f.conductance = conductance;
  } else {
    for (auto& c : f.conductance) c.clear();
  }
  return chain;
}

/// Fits A in value(x) = A exp(-κ |x - x0|) over cells [first, last] (least squares in log).
double amplitude(const ShGrid& light, const MaterialGrid& m, int ch, int first, int last, double kappa, double x0) {
  double sum = 0.0;
  for (int x = first; x <= last; ++x)
    sum += std::log(double(light.plane(ch, 0)[m.frame.index(x, 1, 1)])) + kappa * std::abs(x - x0);
  return std::exp(sum / (last - first + 1));
}

TEST(Diffusivity, LightCrossesAnInterfaceAsDiffusionTheorySays) {
  // A (σs' = 4, σa = 0.1 /mm) and B (σs' = 1, σa = 0.1), cells 0.2 mm: B's D = 1/(3σt') is
  // 3.7x A's. A plane source in A, 15 cells before the interface. Continuum diffusion:
  // the wave transmitted into B has T = 2 Z_A / (Z_A + Z_B) of the incident wave's value
  // at the interface and the reflected one R = (Z_A − Z_B) / (Z_A + Z_B), Z = D κ/Δx with
  // κ the lattice's decay per cell (each medium's own, exact for a plane wave). The
  // lattice with one D everywhere has Z ∝ κ instead: T = 2 κ_A / (κ_A + κ_B), here 2x.
  // Tolerance 4 %: the interface face passes √(w_A w_B) where a finite-volume scheme
  // for piecewise-constant D would pass the harmonic mean (1.2x at this contrast,
  // for one face against the ~9 cells of a decay length).
  const glm::vec3 sigmaTA(4.1f), sigmaSA(4.0f), sigmaTB(1.1f), sigmaSB(1.0f);
  const double dx = 0.2;
  const int cells = 220, interface = 70, source = 55;
  for (const bool vary : {true, false}) {
    Chain chain = makeChain(cells, interface, sigmaTA, sigmaSA, sigmaTB, sigmaSB, dx, vary);
    const MaterialGrid& m = chain.material;
    ShGrid field, light;
    field.resize(m.frame);
    light.resize(m.frame);
    for (int ch = 0; ch < 3; ++ch) field.plane(ch, 0)[m.frame.index(source, 1, 1)] = 1.0f;
    propagate(m, chain.factors, field, light, converged());

    const CellTransport a = calibratedTransport(sigmaTA.x, sigmaSA.x, 0.0, dx, 1.0);
    const CellTransport b = calibratedTransport(sigmaTB.x, sigmaSB.x, 0.0, dx, 1.0);
    const double kappaA = std::acosh(3.0 / a.dc - 2.0), kappaB = std::acosh(3.0 / b.dc - 2.0);
    const double zA = kappaA / (3.0 * sigmaTA.x), zB = kappaB / (3.0 * sigmaTB.x);
    const double distance = interface - 0.5 - source;  // source centre to the interface face
    // Left of the source: the source's wave plus the reflected one, both decaying left.
    const double left = amplitude(light, m, 0, source - 35, source - 10, kappaA, source);
    // In B, measured from the interface face (cell x's centre is x + 0.5 - interface from it).
    const double right = amplitude(light, m, 0, interface + 10, interface + 40, kappaB, interface - 0.5);
    // Impedances: Z = D κ / Δx per medium, or κ alone for the lattice with one D.
    const double impedanceA = vary ? zA : kappaA, impedanceB = vary ? zB : kappaB;
    const double reflected =
        (impedanceA - impedanceB) / (impedanceA + impedanceB) * std::exp(-2.0 * kappaA * distance);
    const double measured = right / left * (1.0 + reflected) / std::exp(-kappaA * distance);
    const double theory = 2.0 * zA / (zA + zB), uniformD = 2.0 * kappaA / (kappaA + kappaB);
    std::printf("[ measured ] %s: T = %.4f, diffusion theory %.4f, one D for all cells %.4f\n",
                vary ? "per-cell D" : "one D", measured, theory, uniformD);
    if (vary)
      EXPECT_NEAR(measured, theory, 0.04 * theory);
    else
      EXPECT_NEAR(measured, uniformD, 0.04 * uniformD) << "the control: the lattice before point 7";
  }
}

}  // namespace

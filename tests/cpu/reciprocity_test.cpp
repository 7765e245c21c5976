// Reciprocity across a material change (docs/design.md §6.7.10). Transport gives the same
// diffuse transmission through a two-layer slab whichever face the light enters. The
// calibrated lattice's per-material gain is split between the cell the light enters
// through and the cell it leaves through (StepFactors::entryCoupling), so the gains no
// longer make it one-sided: with the whole gain on the exit, light leaving through a
// thin absorbing layer took that layer's gain alone (×0.16 of the core's in blue). What
// asymmetry is left is the lattice's own: each face injects at its own material's depth
// and the exit reads the face layer, and the two materials' decay between those differs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lpv_test_grids.h"
#include "volume/cpu/inject.h"
#include "volume/cpu/propagate.h"
#include "volume/lpv/lpv_stages.h"

namespace sslpv::test {
namespace {

/// A medium as σs' and σa per mm (g = 0).
struct Layer {
  glm::vec3 sigmaSPrime, sigmaA;
};

constexpr int kLateral = 24, kLayersA = 4, kLayersB = 8;
constexpr double kCell = 0.25;  // mm: A is 1 mm thick, B 2 mm

/// Per entering power, what shading reads (exit gain times the accumulated power) from the
/// middle of the face opposite the lit one, of a wide slab of A (top) over B, lit along
/// its normal over the whole top face or the whole bottom face.
struct Transmission {
  glm::dvec3 out;        ///< what shading reads from the far face, per entering power
  glm::dvec3 coupling;   ///< the entry coupling of the lit face's material
};

Transmission transmitted(const Layer& a, const Layer& b, bool litFromTop) {
  const int depth = kLayersA + kLayersB + 2;
  MaterialGrid m = uniformMaterial(kLateral, glm::vec3(1.0f), glm::vec3(1.0f), 0.0f, kCell);
  m.frame.dims = glm::ivec3(kLateral, kLateral, depth);
  const std::size_t n = m.frame.cellCount();
  m.coverage.assign(n, 0.0f);
  m.sigmaT.assign(n, glm::vec3(0.0f));
  m.sigmaS.assign(n, glm::vec3(0.0f));
  m.g.assign(n, 0.0f);
  const int bottom = 1, top = depth - 2;  // the slab's first and last layer
  for (int z = bottom; z <= top; ++z)
    for (int y = 1; y < kLateral - 1; ++y)
      for (int x = 1; x < kLateral - 1; ++x) {
        const std::size_t i = m.frame.index(x, y, z);
        const Layer& layer = z > top - kLayersA ? a : b;
        m.coverage[i] = 1.0f;
        m.sigmaS[i] = layer.sigmaSPrime;
        m.sigmaT[i] = layer.sigmaSPrime + layer.sigmaA;
      }
  const StepFactors factors = computeStepFactors(m, LpvScheme::Calibrated, 1.4);

  const float faceZ = float((litFromTop ? top + 1 : bottom) * kCell);
  const glm::vec3 normal(0.0f, 0.0f, litFromTop ? 1.0f : -1.0f);
  std::vector<SurfaceFluxSample> samples;
  for (int y = 1; y < kLateral - 1; ++y)
    for (int x = 1; x < kLateral - 1; ++x)
      samples.push_back({glm::vec3(float((x + 0.5) * kCell), float((y + 0.5) * kCell), faceZ), normal, -normal,
                         glm::vec3(1.0f)});
  ShGrid field, accumulated;
  field.resize(m.frame);
  accumulated.resize(m.frame);
  injectSamples(samples, m, field, &factors);
  PropagationOptions options;
  options.steps = 3000;
  propagate(m, factors, field, accumulated, options);

  const int c = kLateral / 2;
  const std::size_t exitCell = m.frame.index(c, c, litFromTop ? bottom : top);
  const std::size_t entryCell = m.frame.index(c, c, litFromTop ? top : bottom);
  Transmission t;
  for (int ch = 0; ch < 3; ++ch) {
    t.out[ch] = double(factors.exitGain[ch][exitCell]) * accumulated.plane(ch, 0)[exitCell] * SSLPV_FLUX_PER_C0;
    t.coupling[ch] = factors.entryCoupling[ch][entryCell];
  }
  return t;
}

TEST(Reciprocity, ATwoLayerSlabPassesTheSameLightWhicheverFaceItEnters) {
  // The heterogeneous suite's layers: a skin-like absorbing layer (α' 0.92 / 0.70 / 0.42)
  // over a clear core (α' 0.99), and a wax over a dark base.
  const Layer skinLike{{1.1f, 0.95f, 0.8f}, {0.09f, 0.40f, 1.10f}};
  const Layer clearCore{{1.55f, 1.60f, 1.70f}, {0.008f, 0.012f, 0.020f}};
  const Layer wax{{2.2f, 2.4f, 2.6f}, {0.004f, 0.008f, 0.02f}};
  const Layer darkBase{{2.5f, 2.2f, 2.0f}, {0.6f, 1.4f, 2.2f}};
  for (const auto& [a, b] : {std::pair{skinLike, clearCore}, std::pair{wax, darkBase}}) {
    const Transmission down = transmitted(a, b, true), up = transmitted(a, b, false);
    for (int ch = 0; ch < 3; ++ch) {
      ASSERT_GT(down.out[ch], 0.0);
      const double ratio = up.out[ch] / down.out[ch];
      // The whole gain on the exit: each way round times its exit material's gain over
      // its entry material's (gain = coupling²).
      const double couplingRatio = down.coupling[ch] / up.coupling[ch];  // A's over B's
      const double exitOnly = ratio * couplingRatio * couplingRatio;
      std::printf("channel %d: lit through A %.4g, through B %.4g: B / A %.3f (whole gain on the exit: %.3f)\n", ch,
                  down.out[ch], up.out[ch], ratio, exitOnly);
      // Measured 2026-12-05: 1.10 / 0.83 / 0.59 (exit only 0.75 / 0.35 / 0.09) and
      // 1.68 / 2.06 / 2.37 (exit only 1.97 / 4.65 / 10.2).
      EXPECT_LT(std::abs(std::log(ratio)), std::abs(std::log(exitOnly))) << "channel " << ch;
      EXPECT_LT(std::abs(std::log(ratio)), std::log(2.5)) << "channel " << ch;
    }
  }
}

}  // namespace
}  // namespace sslpv::test

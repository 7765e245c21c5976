// A slab whose surface is not aligned with the grid: its boundary is a staircase of cells.
// The calibrated scheme's boundary retention is derived for a face along the grid axes
// (volume/calibration/lpv_calibration.h); computeStepFactors re-derives it for tilted surfaces so that
// the lattice's diffuse profile vanishes at the same extrapolation length beyond the true
// surface. These tests render the same slab, lit and seen along its normal, aligned with
// the grid and tilted, and compare the two SSLPV renders (the aligned one matches the path
// tracer to 0.1 %, docs/accuracy.md). Light injected at the half-cell floor and read
// back before it propagates is diluted over a staircase's cells; computeStepFactors also
// corrects the exit gain for that (staircaseExitCorrection).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/scene.h"

namespace {
using namespace sslpv;

/// A slab 30 x 15 x 30 mm, top face through the origin, rotated by `rotateDeg` (scene
/// order: z, then y, then x), lit by a directional light `incidenceDeg` off its top face's
/// normal and seen along the normal; the camera sees only the central 5 mm of the top face.
Scene tiltedSlab(const std::string& preset, double ior, const glm::dvec3& rotateDeg, double extraDepth = 0.0,
                 double incidenceDeg = 0.0) {
  const glm::dmat4 rotation = Transform{glm::dvec3(0.0), rotateDeg, 1.0}.matrix();
  const glm::dvec3 normal = glm::normalize(glm::dvec3(rotation * glm::dvec4(0, 1, 0, 0)));
  const glm::dvec3 up = glm::normalize(glm::dvec3(rotation * glm::dvec4(0, 0, 1, 0)));
  const double incidence = incidenceDeg * 3.14159265358979323846 / 180.0;
  const glm::dvec3 toLight = std::cos(incidence) * normal + std::sin(incidence) * up;
  auto vec = [](const glm::dvec3& v) {
    return "[" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + "]";
  };
  const std::string json = R"({"units": "mm", "mesh": {"primitive": "box", "min": [-15, )" + std::to_string(-15.0 - extraDepth) + R"(, -15], "max": [15, 0, 15]},
    "transform": {"rotate_deg": )" + vec(rotateDeg) + R"(},
    "material": {"base": {"preset": ")" + preset + R"("}, "ior": )" + std::to_string(ior) + R"(},
    "lights": [{"type": "directional", "direction": )" + vec(-toLight) + R"(, "irradiance": [1, 1, 1]}],
    "camera": {"position": )" + vec(200.0 * normal) + R"(, "target": [0, 0, 0], "up": )" + vec(up) + R"(,
               "fov_y_deg": 1.5, "width": 24, "height": 24},
    "lpv": {"resolution": 32, "steps": "auto", "shadow_map": 128}})";
  return parseScene(json, "tilted_slab.json");
}

glm::dvec3 meanRadiance(const Scene& scene) {
  const Image image = CpuRenderer(scene).render(scene.lpv);
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return sum / double(image.pixels.size());
}

// The same slab tilted by 30° and 45° about one axis, against the aligned slab. Where a
// tilted face falls within its cells varies along it and with the grid's phase (an
// aligned face's phase is corrected, next test), so the tilted slab is averaged over
// three phases (the slab 0, 0.4 and 0.8 mm deeper, which
// shifts the grid that follows its bounds) and compared with the aligned slab in its
// calibrated phase (top face on a cell face, where it matches the path tracer to 0.1 %).
// Before the staircase model (one flat ρ on every face of the staircase, no correction of
// unpropagated light): ketchup red x0.92 / x0.90, its blue x0.83 / x0.85, marble x1.10.
// Measured now (30° / 45°, R G B): ketchup 0.96 1.00 0.94 / 0.97 1.01 0.93, marble
// 0.95 0.96 0.97 / 0.94 0.94 0.96, skin 1.00 0.96 0.91 / 1.01 0.96 0.89. Marble's partly
// covered cells read 1.02 1.08 1.11 / 1.01 1.05 1.07 while their retention was clamped
// at 0 (kMinRetention). The red channels, diffusion-dominated, must stay within 7 %
// (the defect above was 8-10 %); the others, where the unpropagated share leaves ~10 %,
// within 12 %.
TEST(TiltedBoundary, ChannelsReflectAsTheAlignedSlabOverGridPhases) {
  struct Case {
    const char* preset;
    double ior;
  };
  for (const Case& c : {Case{"ketchup", 1.3}, Case{"marble", 1.5}, Case{"skin1", 1.4}}) {
    const glm::dvec3 aligned = meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0)));
    for (double tilt : {30.0, 45.0}) {
      glm::dvec3 tilted(0.0);
      for (double extra : {0.0, 0.4, 0.8})
        tilted += meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0, 0.0, tilt), extra)) / 3.0;
      std::printf("[ measured ] %s tilted %.0f: %.3f %.3f %.3f of the aligned slab\n", c.preset, tilt,
                  tilted.x / aligned.x, tilted.y / aligned.y, tilted.z / aligned.z);
      for (int ch = 0; ch < 3; ++ch) {
        ASSERT_GT(aligned[ch], 0.0) << c.preset;
        const double tolerance = ch == 0 ? 0.07 : 0.12;
        EXPECT_NEAR(tilted[ch] / aligned[ch], 1.0, tolerance) << c.preset << " channel " << ch << " tilted " << tilt;
      }
    }
  }
}

// The aligned slab itself at five grid phases: 0.2 to 0.8 mm deeper moves its top face to
// coverage 0.6, 0.7, 0.8 and 0.9 of its boundary cells (Δx = 1 mm; a grid centred on the
// bounds never puts a face under 0.5), lit along the normal and at 60° and 80°, against the
// face on a cell boundary. Without the phase corrections (R G B ranges over the phases):
// normal incidence ketchup 0.99-1.00 0.84-0.93 0.67-0.84, marble 0.86-0.93 0.83-0.92
// 0.81-0.91, skin1 0.99-1.03 0.87-0.93 0.69-0.85 (before gridPhaseFreshGain); 80° ketchup
// green 0.76-1.01, skin1 0.93-0.99 0.84-1.01 0.87-1.01 (with the fresh gain, before
// the phase oblique factors). With both every channel is within 0.989-1.013. Each must stay
// within 3 %.
TEST(TiltedBoundary, AlignedSlabReflectsTheSameAtEveryGridPhase) {
  struct Case {
    const char* preset;
    double ior;
  };
  for (const Case& c : {Case{"ketchup", 1.3}, Case{"marble", 1.5}, Case{"skin1", 1.4}})
    for (double incidence : {0.0, 60.0, 80.0}) {
      const glm::dvec3 onFace = meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0), 0.0, incidence));
      glm::dvec3 low(1e30), high(0.0);
      for (double extra : {0.2, 0.4, 0.6, 0.8}) {
        const glm::dvec3 phased =
            meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0), extra, incidence)) / onFace;
        low = glm::min(low, phased);
        high = glm::max(high, phased);
      }
      std::printf("[ measured ] %s aligned, lit at %.0f deg, face inside its cells: %.3f-%.3f %.3f-%.3f %.3f-%.3f\n",
                  c.preset, incidence, low.x, high.x, low.y, high.y, low.z, high.z);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(low[ch], 1.0, 0.03) << c.preset << " channel " << ch << " incidence " << incidence;
        EXPECT_NEAR(high[ch], 1.0, 0.03) << c.preset << " channel " << ch << " incidence " << incidence;
      }
    }
}

// A tilted face takes every phase along it. Lit obliquely its light sits shallower, where
// the phase matters more. Tilted 30° over aligned, at 60° / 80° incidence, relative to the
// same ratio at normal incidence, before the phase oblique factors: ketchup 1.01 0.90 0.93 /
// 1.02 0.86 0.94, skin1 0.97 0.93 0.94 / 0.96 0.91 0.94 (marble within 3 %). After: all
// within 0.997-1.027. Each must stay within 3 % (the staircase's own error at normal
// incidence is the first test's).
TEST(TiltedBoundary, TiltedSlabLitObliquelyKeepsItsNormalIncidenceRatio) {
  struct Case {
    const char* preset;
    double ior;
  };
  for (const Case& c : {Case{"ketchup", 1.3}, Case{"marble", 1.5}, Case{"skin1", 1.4}}) {
    const auto ratio = [&](double incidence) {
      glm::dvec3 tilted(0.0);
      for (double extra : {0.0, 0.4, 0.8})
        tilted += meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0, 0.0, 30.0), extra, incidence)) / 3.0;
      return tilted / meanRadiance(tiltedSlab(c.preset, c.ior, glm::dvec3(0.0), 0.0, incidence));
    };
    const glm::dvec3 normal = ratio(0.0);
    for (double incidence : {60.0, 80.0}) {
      const glm::dvec3 oblique = ratio(incidence) / normal;
      std::printf("[ measured ] %s tilted 30, lit at %.0f deg: %.3f %.3f %.3f of its ratio at normal incidence\n",
                  c.preset, incidence, oblique.x, oblique.y, oblique.z);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(oblique[ch], 1.0, 0.03) << c.preset << " channel " << ch << " incidence " << incidence;
    }
  }
}

}  // namespace

// End-to-end CPU renders: the shipped examples and properties any correct render has.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "test_support.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/scene.h"

namespace {
using namespace sslpv;

struct ImageSummary {
  double sum = 0.0, max = 0.0;
  std::size_t lit = 0, nonFinite = 0, negative = 0;
};

ImageSummary summarize(const Image& image) {
  ImageSummary s;
  for (const glm::vec3& p : image.pixels)
    for (int ch = 0; ch < 3; ++ch) {
      if (!std::isfinite(p[ch])) {
        ++s.nonFinite;
        continue;
      }
      if (p[ch] < 0.0f) ++s.negative;
      s.sum += p[ch];
      s.max = std::max(s.max, double(p[ch]));
    }
  for (const glm::vec3& p : image.pixels) s.lit += (p.x + p.y + p.z) > 0.0f;
  return s;
}

TEST(RenderExamples, EveryShippedExampleIsFiniteNonNegativeAndLit) {
  int rendered = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::examplesDir())) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    Scene scene = loadScene(entry.path());
    CpuRenderer renderer(scene);
    RenderReport report;
    const Image image = renderer.render(scene.lpv, &report);
    const ImageSummary s = summarize(image);
    EXPECT_EQ(s.nonFinite, 0u);
    EXPECT_EQ(s.negative, 0u);
    EXPECT_GT(s.lit, image.pixels.size() / 50) << "the object must cover and light part of the frame";
    EXPECT_GT(s.max, 1e-4);
    EXPECT_GT(report.activeCells, 0u);
    if (scene.lpv.autoSteps) {
      EXPECT_GT(report.propagation.stepsRun, 8) << "the calibrated scheme needs more than 8 steps to settle";
      EXPECT_LT(report.propagation.stepsRun, PropagationOptions{}.maxAutoSteps) << "auto steps must stop";
    } else {
      EXPECT_EQ(report.propagation.stepsRun, scene.lpv.steps);
    }
    ++rendered;
  }
  EXPECT_GE(rendered, 3) << "examples/ should ship several scenes";
}

const char* kSlabScene = R"({
  "mesh": {"primitive": "box", "min": [-10, -10, -2], "max": [10, 10, 2]},
  "material": {"base": {"sigma_t": [1.0, 1.2, 1.5], "sigma_s": [0.95, 1.0, 0.9], "g": 0.2}, "ior": 1.3},
  "lights": [{"type": "spot", "position": [5, 5, 40], "direction": [0, 0, -1], "fov_deg": 30,
              "intensity": [1000, 1000, 1000]},
             {"type": "directional", "direction": [0, 0, 1], "irradiance": [0.5, 0.5, 0.5]}],
  "camera": {"position": [0, -30, 40], "target": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 40,
             "width": 96, "height": 96},
  "lpv": {"resolution": 20, "steps": 12, "shadow_map": 96}
})";

TEST(RenderProperties, RadianceIsLinearInLightPower) {
  Scene scene = parseScene(kSlabScene, "slab.json");
  const Image base = CpuRenderer(scene).render(scene.lpv);
  for (Light& l : scene.lights) {
    l.intensity *= 2.0f;
    l.irradiance *= 2.0f;
  }
  const Image doubled = CpuRenderer(scene).render(scene.lpv);
  ASSERT_GT(summarize(base).sum, 0.0);
  for (std::size_t i = 0; i < base.pixels.size(); ++i)
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_NEAR(doubled.pixels[i][ch], 2.0f * base.pixels[i][ch], 1e-5f * (1.0f + base.pixels[i][ch]));
}

TEST(RenderProperties, AbsorptionDarkensTheImage) {
  Scene scene = parseScene(kSlabScene, "slab.json");
  const double bright = summarize(CpuRenderer(scene).render(scene.lpv)).sum;
  scene.material.base.sigmaS *= 0.3f;
  const double dark = summarize(CpuRenderer(scene).render(scene.lpv)).sum;
  EXPECT_LT(dark, 0.8 * bright);
  EXPECT_GT(dark, 0.0);
}

TEST(RenderProperties, BackgroundStaysBlack) {
  Scene scene = parseScene(kSlabScene, "slab.json");
  scene.camera.target = glm::dvec3(0, 0, 400);  // looking away from the slab
  const ImageSummary s = summarize(CpuRenderer(scene).render(scene.lpv));
  EXPECT_EQ(s.sum, 0.0);
}

TEST(RenderProperties, MoreStepsCarryLightFurther) {
  // Light entering at the top must cross the slab to reach the bottom face; with one
  // step the lattice cannot carry it there, with enough steps it does. (The calibrated
  // shading's single-scattering term, which needs no steps, is in all three images: the
  // lattice's share is each image less the one without steps.)
  Scene scene = parseScene(kSlabScene, "slab.json");
  scene.lights.resize(1);  // only the spot from above
  scene.camera.position = glm::dvec3(0, -30, -40);
  LpvSettings settings = scene.lpv;
  settings.steps = 0;
  const double none = summarize(CpuRenderer(scene).render(settings)).sum;
  settings.steps = 1;
  const double few = summarize(CpuRenderer(scene).render(settings)).sum - none;
  settings.steps = 30;
  const double many = summarize(CpuRenderer(scene).render(settings)).sum - none;
  EXPECT_GT(many, 10.0 * few + 1e-12);
}

}  // namespace

// The Vulkan backend as a user drives it: dirty flags that skip unchanged stages, and
// the command line's behaviour without a usable Vulkan device.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "gpu/vulkan_renderer.h"
#include "gpu_test_fixture.h"
#include "test_support.h"
#include "volume/scene/scene.h"

namespace {
using namespace sslpv;

Scene pebbleScene() {
  Scene scene = loadScene(test::examplesDir() / "marble_pebble.json");
  scene.camera.width = scene.camera.height = 128;
  scene.lpv.autoSteps = false;  // fixed steps: the step-change checks count them
  scene.lpv.steps = 8;
  return scene;
}

/// Largest |a - b| relative to the largest value of b: float atomics in injection add
/// in a different order on every run, so GPU frames agree to rounding, not bit for bit.
double maxRelativeDifference(const Image& a, const Image& b) {
  double worst = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int ch = 0; ch < 3; ++ch) {
      worst = std::max(worst, double(std::abs(a.pixels[i][ch] - b.pixels[i][ch])));
      peak = std::max(peak, double(b.pixels[i][ch]));
    }
  return peak > 0.0 ? worst / peak : worst;
}

using GpuRenderer = test::GpuTest;

TEST_F(GpuRenderer, CameraMoveReshadesOnly) {
  Scene scene = pebbleScene();
  gpu::VulkanRenderer renderer(scene, device());
  renderer.render(scene.lpv);
  scene.camera.position = glm::dvec3(40.0, 30.0, 70.0);
  renderer.setCamera(scene.camera);
  RenderReport report;
  const Image moved = renderer.render(scene.lpv, &report);
  for (Stage s : {Stage::Voxelize, Stage::Resample, Stage::ShadowMap, Stage::Injection, Stage::Propagation})
    EXPECT_TRUE(report.times.cached(s)) << "stage " << unsigned(s) << " should not re-run for a camera move";
  EXPECT_FALSE(report.times.cached(Stage::Shading));
  EXPECT_LT(maxRelativeDifference(moved, gpu::VulkanRenderer(scene, device()).render(scene.lpv)), 1e-4);
}

TEST_F(GpuRenderer, LightAndStepChangesRerunFromTheirStage) {
  Scene scene = pebbleScene();
  gpu::VulkanRenderer renderer(scene, device());
  renderer.render(scene.lpv);
  scene.lights[0].intensity *= 0.5;
  renderer.setLights(scene.lights);
  RenderReport report;
  Image image = renderer.render(scene.lpv, &report);
  EXPECT_TRUE(report.times.cached(Stage::Voxelize) && report.times.cached(Stage::Resample));
  EXPECT_FALSE(report.times.cached(Stage::ShadowMap));
  EXPECT_LT(maxRelativeDifference(image, gpu::VulkanRenderer(scene, device()).render(scene.lpv)), 1e-4);

  LpvSettings more = scene.lpv;
  more.steps *= 2;
  image = renderer.render(more, &report);
  EXPECT_TRUE(report.times.cached(Stage::ShadowMap) && report.times.cached(Stage::Injection));
  EXPECT_EQ(report.propagation.stepsRun, more.steps);
  EXPECT_LT(maxRelativeDifference(image, gpu::VulkanRenderer(scene, device()).render(more)), 1e-4);
}

TEST(GpuCommandLine, MissingVulkanDeviceIsAOneLineErrorAndTheCpuBackendStillWorks) {
  test::TempDir dir;
  const auto out = dir.path() / "out.png";
  const std::string scene = (test::examplesDir() / "skin_sphere.json").string();
  // Selecting a device that does not exist stands in for a machine without one.
  setenv("SSLPV_VULKAN_DEVICE", "no-such-gpu-anywhere", 1);
  const test::RunResult vulkan = test::runSslpv({"render", scene, "-o", out.string(), "--backend", "vulkan"});
  unsetenv("SSLPV_VULKAN_DEVICE");
  EXPECT_EQ(vulkan.exitCode, 3) << vulkan.stderrText;
  EXPECT_NE(vulkan.stderrText.find("no-such-gpu-anywhere"), std::string::npos) << vulkan.stderrText;
  EXPECT_NE(vulkan.stderrText.find("--backend cpu needs no GPU"), std::string::npos) << vulkan.stderrText;
  EXPECT_FALSE(std::filesystem::exists(out));
  const test::RunResult cpu = test::runSslpv({"render", scene, "-o", out.string(), "--backend", "cpu"});
  EXPECT_EQ(cpu.exitCode, 0) << cpu.stderrText;
  EXPECT_TRUE(std::filesystem::exists(out));
}

}  // namespace

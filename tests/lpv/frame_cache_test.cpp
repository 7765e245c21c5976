// The frame skeleton both backends share (volume/lpv/staged_renderer.h), through the
// Renderer interface: a frame re-runs only the stages whose inputs changed, and what it
// produces is what a fresh renderer computes from the changed scene. One suite, run on
// each backend: bit for bit on the CPU, to float rounding on Vulkan (injection adds with
// float atomics in a different order on every run).
#include <gtest/gtest.h>

#include <glm/mat4x4.hpp>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <ostream>

#include "backend/backends.h"
#include "test_support.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"
#ifdef SSLPV_HAVE_VULKAN
#include "gpu_test_fixture.h"
#endif

namespace sslpv {
// The parameter's name in test listings, instead of its bytes.
void PrintTo(BackendKind kind, std::ostream* out) { *out << (kind == BackendKind::Cpu ? "cpu" : "vulkan"); }
}  // namespace sslpv

namespace {
using namespace sslpv;

Scene pebbleScene() {
  Scene scene = loadScene(test::examplesDir() / "marble_pebble.json");
  scene.camera.width = scene.camera.height = 96;  // small: the checks are per pixel
  scene.lpv.shadowMap = 96;
  scene.lpv.autoSteps = false;  // fixed steps: the step-change checks count them
  scene.lpv.steps = 8;
  return scene;
}

bool anyLit(const Image& image) {
  for (const glm::vec3& p : image.pixels)
    if (p.x + p.y + p.z > 0.0f) return true;
  return false;
}

class FrameCache : public ::testing::TestWithParam<BackendKind> {
 protected:
  void SetUp() override {
    if (GetParam() == BackendKind::Cpu) {
      backends_ = std::make_unique<Backends>(BackendKind::Cpu);
      return;
    }
#ifdef SSLPV_HAVE_VULKAN
    if (!device_.open()) GTEST_SKIP() << device_.skipReason();
    backends_ = std::make_unique<Backends>(BackendKind::Vulkan, device_.device());
#else
    GTEST_SKIP() << "SKIPPED, this build has no Vulkan backend";
#endif
  }

  void TearDown() override {
    backends_.reset();
#ifdef SSLPV_HAVE_VULKAN
    device_.closeAndCheck();
#endif
  }

  std::unique_ptr<Renderer> make(const Scene& scene) { return backends_->make(scene); }
  Image fresh(const Scene& scene, const LpvSettings& settings,
              std::shared_ptr<const MaterialSet> set = nullptr) {
    std::unique_ptr<Renderer> renderer = make(scene);
    if (set) renderer->setMaterialSet(std::move(set), std::nullopt);
    return renderer->render(settings);
  }

  void expectSameImage(const Image& a, const Image& b) {
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    if (GetParam() == BackendKind::Cpu) {
      std::size_t differing = 0;
      for (std::size_t i = 0; i < a.pixels.size(); ++i) differing += a.pixels[i] != b.pixels[i];
      EXPECT_EQ(differing, 0u) << "a cached stage must give bit-identical results";
      return;
    }
    // Largest |a - b| relative to the largest value of b.
    double worst = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
      for (int ch = 0; ch < 3; ++ch) {
        worst = std::max(worst, double(std::abs(a.pixels[i][ch] - b.pixels[i][ch])));
        peak = std::max(peak, double(b.pixels[i][ch]));
      }
    EXPECT_LT(peak > 0.0 ? worst / peak : worst, 1e-4) << "a cached stage must give the fresh frame to rounding";
  }

 private:
#ifdef SSLPV_HAVE_VULKAN
  test::ValidatedDevice device_;
#endif
  std::unique_ptr<Backends> backends_;
};

TEST_P(FrameCache, CameraMoveReshadesOnlyAndMatchesAFreshRender) {
  Scene scene = pebbleScene();
  std::unique_ptr<Renderer> renderer = make(scene);
  renderer->render(scene.lpv);
  scene.camera.position = glm::dvec3(40.0, 30.0, 70.0);
  renderer->setCamera(scene.camera);
  RenderReport report;
  const Image moved = renderer->render(scene.lpv, &report);
  for (Stage s : {Stage::Voxelize, Stage::Resample, Stage::ShadowMap, Stage::Injection, Stage::Propagation})
    EXPECT_TRUE(report.times.cached(s)) << "stage " << unsigned(s) << " should not re-run for a camera move";
  EXPECT_FALSE(report.times.cached(Stage::Shading));
  EXPECT_EQ(report.times.shadowMap + report.times.injection + report.times.propagation, 0.0);
  EXPECT_TRUE(anyLit(moved));
  expectSameImage(moved, fresh(scene, scene.lpv));
}

TEST_P(FrameCache, LightChangeRerunsShadowMapsOnwardsAndMatchesAFreshRender) {
  Scene scene = pebbleScene();
  std::unique_ptr<Renderer> renderer = make(scene);
  renderer->render(scene.lpv);
  scene.lights[1].position += glm::dvec3(0.0, 40.0, 0.0);
  scene.lights[0].intensity *= 0.5;
  renderer->setLights(scene.lights);
  RenderReport report;
  const Image image = renderer->render(scene.lpv, &report);
  EXPECT_TRUE(report.times.cached(Stage::Voxelize));
  EXPECT_TRUE(report.times.cached(Stage::Resample));
  EXPECT_FALSE(report.times.cached(Stage::ShadowMap));
  EXPECT_FALSE(report.times.cached(Stage::Propagation));
  expectSameImage(image, fresh(scene, scene.lpv));
}

TEST_P(FrameCache, StepChangeRepropagatesFromTheKeptInjectedLight) {
  Scene scene = pebbleScene();
  std::unique_ptr<Renderer> renderer = make(scene);
  renderer->render(scene.lpv);
  LpvSettings more = scene.lpv;
  more.steps = scene.lpv.steps * 2;
  RenderReport report;
  const Image image = renderer->render(more, &report);
  EXPECT_TRUE(report.times.cached(Stage::ShadowMap));
  EXPECT_TRUE(report.times.cached(Stage::Injection));
  EXPECT_EQ(report.propagation.stepsRun, more.steps);
  expectSameImage(image, fresh(scene, more));
}

/// A brush stroke: a block of dark, absorbing voxels just under the surface the camera
/// sees (the pebble's top front; the set's voxels are 0.8 mm).
struct Stroke {
  std::shared_ptr<const MaterialSet> set;
  Bounds worldBounds;  ///< everything the changed voxels influence (trilinear support)
};

Stroke paintStroke(const Scene& scene) {
  const auto original = loadMaterialSet(*scene.material.vdb);
  auto painted = std::make_shared<MaterialSet>(*original);
  painted->sigmaT = openvdb::gridPtrCast<openvdb::Vec3SGrid>(original->sigmaT->deepCopyGrid());
  painted->sigmaS = openvdb::gridPtrCast<openvdb::Vec3SGrid>(original->sigmaS->deepCopyGrid());
  const openvdb::CoordBBox block(openvdb::Coord(-4, 4, 8), openvdb::Coord(4, 12, 18));
  auto t = painted->sigmaT->getAccessor();
  auto s = painted->sigmaS->getAccessor();
  for (auto ijk = block.begin(); ijk; ++ijk) {
    t.setValue(*ijk, openvdb::Vec3s(3.0f, 3.0f, 3.0f));
    s.setValue(*ijk, openvdb::Vec3s(0.6f, 0.6f, 0.6f));
  }
  // Trilinear reads see a voxel within one voxel of it; map that box to world space.
  const glm::dmat4 restToWorld = scene.transform.matrix();
  Bounds world;
  for (int corner = 0; corner < 8; ++corner) {
    const openvdb::Vec3d index(corner & 1 ? block.max().x() + 1 : block.min().x() - 1,
                               corner & 2 ? block.max().y() + 1 : block.min().y() - 1,
                               corner & 4 ? block.max().z() + 1 : block.min().z() - 1);
    const openvdb::Vec3d rest = painted->sigmaT->transform().indexToWorld(index);
    world.extend(glm::dvec3(restToWorld * glm::dvec4(rest.x(), rest.y(), rest.z(), 1.0)));
  }
  return {painted, world};
}

TEST_P(FrameCache, BrushStrokeResamplesOnlyItsRegionAndMatchesAFullResample) {
  Scene scene = pebbleScene();
  const Stroke stroke = paintStroke(scene);
  std::unique_ptr<Renderer> renderer = make(scene);
  RenderReport first;
  const Image before = renderer->render(scene.lpv, &first);
  renderer->setMaterialSet(stroke.set, stroke.worldBounds);
  RenderReport report;
  const Image after = renderer->render(scene.lpv, &report);
  EXPECT_GT(report.resampledCells, 0u);
  EXPECT_LT(report.resampledCells, first.frame.cellCount() / 10) << "a small stroke resamples a small region";
  EXPECT_TRUE(report.times.cached(Stage::ShadowMap));
  // The calibrated injection depth follows the material.
  EXPECT_FALSE(report.times.cached(Stage::Injection));
  EXPECT_FALSE(report.times.cached(Stage::Propagation));
  expectSameImage(after, fresh(scene, scene.lpv, stroke.set));
  std::size_t changed = 0;
  for (std::size_t i = 0; i < after.pixels.size(); ++i) changed += after.pixels[i] != before.pixels[i];
  EXPECT_GT(changed, 0u) << "the stroke must be visible, or the test checks nothing";

  // The CPU's stroke frame kept the single-scattering term of the pixels that read no
  // painted cell; a camera move afterwards must not reuse any of it.
  scene.camera.position = glm::dvec3(40.0, 30.0, 70.0);
  renderer->setCamera(scene.camera);
  expectSameImage(renderer->render(scene.lpv), fresh(scene, scene.lpv, stroke.set));
}

std::string backendName(const ::testing::TestParamInfo<BackendKind>& info) {
  return info.param == BackendKind::Cpu ? "Cpu" : "Vulkan";
}

INSTANTIATE_TEST_SUITE_P(EachBackend, FrameCache, ::testing::Values(BackendKind::Cpu, BackendKind::Vulkan),
                         backendName);

TEST(StageDirty, EachChangeMarksItsFirstStageAndEverythingDownstream) {
  StageDirty dirty;
  dirty.clear();
  dirty.cameraChanged();
  EXPECT_TRUE(dirty.dirty(Stage::Shading));
  EXPECT_FALSE(dirty.dirty(Stage::Propagation));
  dirty.clear();
  dirty.lightsChanged();
  EXPECT_TRUE(dirty.dirty(Stage::ShadowMap) && dirty.dirty(Stage::Injection) &&
              dirty.dirty(Stage::Propagation) && dirty.dirty(Stage::Shading));
  EXPECT_FALSE(dirty.dirty(Stage::Resample) || dirty.dirty(Stage::Voxelize));
  dirty.clear();
  Bounds a{glm::dvec3(0), glm::dvec3(1)}, b{glm::dvec3(5), glm::dvec3(6)};
  dirty.materialChanged(a);
  dirty.materialChanged(b);
  ASSERT_TRUE(dirty.resampleRegion());
  EXPECT_EQ(dirty.resampleRegion()->min, glm::dvec3(0));
  EXPECT_EQ(dirty.resampleRegion()->max, glm::dvec3(6)) << "two strokes before a frame: their union";
  EXPECT_FALSE(dirty.dirty(Stage::ShadowMap) || dirty.dirty(Stage::Voxelize));
  // The calibrated injection depth follows the material: injection onwards rerun.
  EXPECT_TRUE(dirty.dirty(Stage::Injection) && dirty.dirty(Stage::Propagation) && dirty.dirty(Stage::Shading));
  dirty.materialChanged(std::nullopt);
  EXPECT_FALSE(dirty.resampleRegion()) << "a whole-material change wins over a region";
  dirty.clear();
  LpvSettings before, after;
  after.steps = before.steps + 1;
  dirty.settingsChanged(before, after);
  EXPECT_TRUE(dirty.dirty(Stage::Propagation));
  EXPECT_FALSE(dirty.dirty(Stage::ShadowMap));
  after.resolution = before.resolution * 2;
  dirty.settingsChanged(before, after);
  EXPECT_TRUE(dirty.dirty(Stage::Voxelize));
}

}  // namespace

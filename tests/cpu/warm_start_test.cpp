// Warm-started propagation: after a material stroke or a light nudge, --steps auto starts
// its semi-iteration from the previous frame's converged light. It must land as close to
// the converged lattice as a cold start does, in fewer steps, and a renderer's
// warm-started frame must match a fresh renderer's cold one. A cold frame starts from the
// same frame solved on a coarser grid (volume/cpu/coarse_start.h), under the same bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <openvdb/openvdb.h>

#include "lpv_test_grids.h"
#include "test_support.h"
#include "volume/cpu/coarse_start.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/eval/image_metrics.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"
#include "volume/cpu/propagate.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;

/// A nearly white cube (light needs many steps to cross it) lit through its -x face, with a
/// warmer and a colder channel.
struct Slab {
  MaterialGrid material;
  ShGrid injected;
};
Slab litCube(int dims) {
  Slab s;
  s.material = uniformMaterial(dims, glm::vec3(1.0f), glm::vec3(0.998f, 0.99f, 0.95f), 0.0f);
  s.injected.resize(s.material.frame);
  for (int z = 1; z < dims - 1; ++z)
    for (int y = 1; y < dims - 1; ++y)
      for (int ch = 0; ch < 3; ++ch) s.injected.plane(ch, 0)[s.material.frame.index(1, y, z)] = 1.0f;
  return s;
}

struct SlabRun {
  PropagationResult result;
  ShGrid accumulated;
};
SlabRun propagateSlab(const Slab& s, PropagationOptions options) {
  const StepFactors factors = computeStepFactors(s.material, LpvScheme::Calibrated, 1.4);
  SlabRun r;
  ShGrid field = s.injected;
  r.accumulated.resize(s.material.frame);
  options.autoSteps = true;
  r.result = propagate(s.material, factors, field, r.accumulated, options);
  return r;
}

/// Σ |a - b| / Σ |b| over every channel's c0, worst channel.
double relativeL1(const ShGrid& a, const ShGrid& b) {
  double worst = 0.0;
  for (int ch = 0; ch < 3; ++ch) {
    double difference = 0.0, total = 0.0;
    for (std::size_t i = 0; i < b.planes[std::size_t(ch) * 4].size(); ++i) {
      difference += std::abs(double(a.planes[std::size_t(ch) * 4][i]) - b.planes[std::size_t(ch) * 4][i]);
      total += std::abs(double(b.planes[std::size_t(ch) * 4][i]));
    }
    worst = std::max(worst, difference / total);
  }
  return worst;
}

/// The largest |a - b| / b over cells holding at least 1e-2 of the mean cell's light.
double maxCellRelative(const ShGrid& a, const ShGrid& b) {
  double worst = 0.0;
  for (int ch = 0; ch < 3; ++ch) {
    const std::vector<float>& x = a.planes[std::size_t(ch) * 4];
    const std::vector<float>& ref = b.planes[std::size_t(ch) * 4];
    double total = 0.0;
    std::size_t lit = 0;
    for (float v : ref) total += v, lit += v > 0.0f;
    const double floor = 1e-2 * total / double(std::max<std::size_t>(lit, 1));
    for (std::size_t i = 0; i < ref.size(); ++i)
      if (ref[i] > floor) worst = std::max(worst, std::abs(double(x[i]) - ref[i]) / ref[i]);
  }
  return worst;
}

/// The plain steps run to 1e-9: the converged lattice both starts are measured against.
ShGrid convergedLight(const Slab& s) {
  PropagationOptions o;
  o.autoTolerance = o.autoTailTolerance = 1e-9;
  o.maxAutoSteps = 100000;
  const SlabRun r = propagateSlab(s, o);
  EXPECT_FALSE(r.result.capped);
  return r.accumulated;
}

TEST(WarmStart, AStrokeOrANudgeReconvergesToTheColdTolerancesInFewerSteps) {
  // The stop rule bounds the light still to come by autoTolerance (1e-3) of the whole
  // light whatever the start, so a warm run must land within the bound the cold run is
  // held to (2e-3, Σ|Δ| / Σ, as in the Chebyshev tests of propagate_test), and it must
  // need fewer steps, or warm starting buys nothing. A stroke's error sits in its region,
  // which the total hardly sees: the worst cell is checked too.
  const Slab before = litCube(24);
  PropagationOptions chebyshev;
  chebyshev.chebyshev = true;
  PropagationWarmStart warm;
  PropagationOptions warmOptions = chebyshev;
  warmOptions.warmStart = &warm;
  const SlabRun first = propagateSlab(before, warmOptions);
  EXPECT_FALSE(first.result.warmStarted) << "nothing to start from yet";
  ASSERT_TRUE(warm.holds(before.material.frame));

  Slab stroke = before;  // a darker block just inside the lit face
  for (int z = 9; z < 15; ++z)
    for (int y = 9; y < 15; ++y)
      for (int x = 1; x < 5; ++x) stroke.material.sigmaS[stroke.material.frame.index(x, y, z)] = glm::vec3(0.6f);
  Slab deep = before;  // a large, much darker block deep inside
  for (int z = 8; z < 16; ++z)
    for (int y = 8; y < 16; ++y)
      for (int x = 4; x < 20; ++x) deep.material.sigmaS[deep.material.frame.index(x, y, z)] = glm::vec3(0.3f);
  Slab nudge = before;  // the light 5 % brighter over half the face
  for (int z = 1; z < 12; ++z)
    for (int y = 1; y < 23; ++y)
      for (int ch = 0; ch < 3; ++ch) nudge.injected.plane(ch, 0)[nudge.material.frame.index(1, y, z)] *= 1.05f;

  for (const auto& [name, changed] :
       {std::pair{"stroke", &stroke}, std::pair{"deep stroke", &deep}, std::pair{"nudge", &nudge}}) {
    PropagationWarmStart start = warm;
    PropagationOptions o = chebyshev;
    o.warmStart = &start;
    const SlabRun warmRun = propagateSlab(*changed, o);
    const SlabRun coldRun = propagateSlab(*changed, chebyshev);
    const ShGrid converged = convergedLight(*changed);
    const double warmError = relativeL1(warmRun.accumulated, converged);
    const double coldError = relativeL1(coldRun.accumulated, converged);
    std::printf("%s: cold %d steps (%.2e off the converged lattice, worst cell %.2e), warm %d steps (%.2e, "
                "worst cell %.2e)\n",
                name, coldRun.result.stepsRun, coldError, maxCellRelative(coldRun.accumulated, converged),
                warmRun.result.stepsRun, warmError, maxCellRelative(warmRun.accumulated, converged));
    EXPECT_TRUE(warmRun.result.warmStarted) << name;
    EXPECT_FALSE(warmRun.result.capped) << name;
    EXPECT_LT(warmError, 2e-3) << name;
    // The cold run's worst cell is itself ~1e-2 off; the warm stop holds every cell's
    // estimated remainder under warmLocalTolerance (1e-2), with the same 2x slack for
    // the extrapolation as the total's.
    EXPECT_LT(maxCellRelative(warmRun.accumulated, converged), 2.0 * o.warmLocalTolerance) << name;
    EXPECT_LT(warmRun.result.stepsRun, coldRun.result.stepsRun) << name;
    EXPECT_TRUE(start.holds(changed->material.frame)) << name << ": the run must hand its light on";
  }
}

TEST(WarmStart, AnotherGridOrADarkSourceStartsCold) {
  const Slab small = litCube(12), large = litCube(16);
  PropagationWarmStart warm;
  PropagationOptions o;
  o.chebyshev = true;
  o.warmStart = &warm;
  propagateSlab(small, o);
  const SlabRun other = propagateSlab(large, o);
  EXPECT_FALSE(other.result.warmStarted) << "a light on another grid is no start";
  EXPECT_TRUE(warm.holds(large.material.frame));

  // With no source the cold path's probe finds the grid dark at once; iterating the old
  // light down to nothing would take a whole run.
  Slab dark = large;
  dark.injected.resize(dark.material.frame);
  const SlabRun darkRun = propagateSlab(dark, o);
  EXPECT_FALSE(darkRun.result.warmStarted);
  EXPECT_EQ(darkRun.result.stepsRun, 2) << "the first step and one probe step";
}

Scene pebbleScene() {
  Scene scene = loadScene(examplesDir() / "marble_pebble.json");
  scene.camera.width = scene.camera.height = 96;
  scene.lpv.shadowMap = 96;
  scene.lpv.autoSteps = true;
  return scene;
}

/// Mean over lit pixels of |a - b| / b (luminance), and the largest such ratio.
struct ImageDifference {
  double mean = 0.0, max = 0.0;
};
ImageDifference relativeDifference(const Image& a, const Image& b) {
  ImageDifference d;
  std::size_t lit = 0;
  for (std::size_t i = 0; i < b.pixels.size(); ++i) {
    const double reference = luminance(b.pixels[i]);
    if (!(reference > 0.0)) continue;
    const double r = std::abs(luminance(a.pixels[i]) - reference) / reference;
    d.mean += r;
    d.max = std::max(d.max, r);
    ++lit;
  }
  EXPECT_GT(lit, 100u) << "the comparison needs a lit object";
  d.mean /= double(std::max<std::size_t>(lit, 1));
  return d;
}

TEST(WarmStart, ARenderersWarmFramesMatchAFreshRenderersColdOnes) {
  // Warm and cold frames each hold the light within autoTolerance (1e-3, L1 over the grid)
  // of the converged lattice, and shading is linear in that light with positive weights,
  // so their images may differ by about twice that on average: the bound is 2e-3 + 2e-3.
  // A single pixel reads a few cells, so its difference is reported, not bounded.
  Scene scene = pebbleScene();
  CpuRenderer renderer(scene);
  RenderReport first;
  renderer.render(scene.lpv, &first);
  EXPECT_FALSE(first.propagation.warmStarted);

  const auto expectMatchesCold = [&](const char* name, const std::shared_ptr<const MaterialSet>& set) {
    RenderReport warm, cold;
    const Image warmImage = renderer.render(scene.lpv, &warm);
    CpuRenderer fresh(scene);
    if (set) fresh.setMaterialSet(set, std::nullopt);
    const Image coldImage = fresh.render(scene.lpv, &cold);
    const ImageDifference d = relativeDifference(warmImage, coldImage);
    std::printf("%s: cold %d steps, warm %d steps; warm vs cold image: mean %.2e, max %.2e (relative)\n", name,
                cold.propagation.stepsRun, warm.propagation.stepsRun, d.mean, d.max);
    EXPECT_TRUE(warm.propagation.warmStarted) << name;
    EXPECT_FALSE(cold.propagation.warmStarted) << name;
    EXPECT_LT(warm.propagation.stepsRun, cold.propagation.stepsRun) << name;
    EXPECT_LT(d.mean, 4e-3) << name;
  };

  scene.lights[0].position += glm::dvec3(0.5, 0.0, 0.0);
  renderer.setLights(scene.lights);
  expectMatchesCold("light nudge", nullptr);

  const auto original = loadMaterialSet(*scene.material.vdb);
  auto painted = std::make_shared<MaterialSet>(*original);
  painted->sigmaS = openvdb::gridPtrCast<openvdb::Vec3SGrid>(original->sigmaS->deepCopyGrid());
  auto s = painted->sigmaS->getAccessor();
  const openvdb::CoordBBox block(openvdb::Coord(-4, 4, 8), openvdb::Coord(4, 12, 18));
  for (auto ijk = block.begin(); ijk; ++ijk) s.setValue(*ijk, s.getValue(*ijk) * 0.5f);
  // The region only limits what is resampled (frame_cache_test checks that); here every
  // cell is, so the cold frame sees the same material, and the change still counts as a
  // stroke.
  Bounds everything;
  everything.extend(glm::dvec3(-1e6));
  everything.extend(glm::dvec3(1e6));
  // The renderer starts strokes cold (see CpuRenderer::setMaterialSet): the same image as
  // a fresh renderer's.
  renderer.setMaterialSet(painted, everything);
  {
    RenderReport afterStroke, cold;
    const Image strokeImage = renderer.render(scene.lpv, &afterStroke);
    CpuRenderer fresh(scene);
    fresh.setMaterialSet(painted, std::nullopt);
    const Image coldImage = fresh.render(scene.lpv, &cold);
    EXPECT_FALSE(afterStroke.propagation.warmStarted);
    EXPECT_EQ(afterStroke.propagation.stepsRun, cold.propagation.stepsRun);
    EXPECT_LT(relativeDifference(strokeImage, coldImage).max, 1e-5);
  }

  // A whole new material set is a new problem: the next frame starts cold.
  renderer.setMaterialSet(painted, std::nullopt);
  RenderReport full;
  renderer.render(scene.lpv, &full);
  EXPECT_FALSE(full.propagation.warmStarted);
  // As does a frame after resetPropagation (frame_bench's full frames).
  renderer.setLights(scene.lights);
  renderer.resetPropagation();
  RenderReport reset;
  renderer.render(scene.lpv, &reset);
  EXPECT_FALSE(reset.propagation.warmStarted);
  EXPECT_EQ(reset.propagation.stepsRun, full.propagation.stepsRun) << "the same cold run as the last frame's";
}

TEST(CoarseStart, ProlongingALinearLightIsExactInsideAndScalesByTheCellArea) {
  // Trilinear interpolation reproduces a linear field wherever all 8 coarse cells are
  // active; a cell's c0 is an intensity through a face of its size, so the fine grid's
  // holds (1/2)² of the coarse one's for the same radiance.
  MaterialGrid coarse = uniformMaterial(10, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f, 2.0);
  MaterialGrid fine = uniformMaterial(20, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f, 1.0);
  const auto linear = [](const glm::dvec3& p, int ch) { return 3.0 + 0.5 * p.x - 0.25 * p.y + 0.125 * (ch + 1) * p.z; };
  std::array<std::vector<float>, 3> light;
  for (int ch = 0; ch < 3; ++ch) {
    light[ch].assign(coarse.frame.cellCount(), 0.0f);
    for (int z = 0; z < 10; ++z)
      for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x)
          light[ch][coarse.frame.index(x, y, z)] = float(linear(coarse.frame.origin + 2.0 * (glm::dvec3(x, y, z) + 0.5), ch));
  }
  std::vector<unsigned char> active(fine.frame.cellCount());
  for (std::size_t i = 0; i < active.size(); ++i) active[i] = fine.coverage[i] > 0.0f;
  const auto fineLight = prolongLight(coarse, light, fine, active);
  int checked = 0;
  // Fine cells 3..16 have their centres between the centres of active coarse cells 1..8.
  for (int z = 3; z <= 16; ++z)
    for (int y = 3; y <= 16; ++y)
      for (int x = 3; x <= 16; ++x)
        for (int ch = 0; ch < 3; ++ch) {
          const glm::dvec3 centre = fine.frame.origin + glm::dvec3(x, y, z) + 0.5;
          EXPECT_NEAR(fineLight[ch][fine.frame.index(x, y, z)], 0.25 * linear(centre, ch), 1e-5) << x << "," << y << "," << z;
          ++checked;
        }
  EXPECT_EQ(checked, 14 * 14 * 14 * 3);
  EXPECT_EQ(fineLight[0][fine.frame.index(0, 5, 5)], 0.0f) << "an inactive fine cell holds no light";
}

TEST(CoarseStart, AColdFrameStartedFromCoarserGridsMatchesAFlatColdOneInFewerSteps) {
  // Both runs stop by the same rule (the light still to come under autoTolerance of the
  // whole), so their images may differ by the warm test's bound; and the coarse start
  // must save fine-grid steps, or it buys nothing. At 32³ one coarser grid (16³) is
  // solved, at 64³ two.
  Scene scene = pebbleScene();
  for (const int resolution : {32, 64}) {
    scene.lpv.resolution = resolution;
    CpuRenderer coarseStarted(scene), flat(scene);
    flat.setCoarseStart(false);
    RenderReport started, cold;
    const Image startedImage = coarseStarted.render(scene.lpv, &started);
    const Image coldImage = flat.render(scene.lpv, &cold);
    const ImageDifference d = relativeDifference(startedImage, coldImage);
    std::printf("%d³: flat cold %d steps; coarse-started %d steps + %d on %d coarser grid(s); image: mean %.2e, max %.2e\n",
                resolution, cold.propagation.stepsRun, started.propagation.stepsRun, started.coarseStart.steps,
                started.coarseStart.levels, d.mean, d.max);
    EXPECT_EQ(started.coarseStart.levels, resolution == 32 ? 1 : 2);
    EXPECT_TRUE(started.propagation.coarseStarted);
    EXPECT_FALSE(started.propagation.warmStarted) << "a previous frame's light is another start";
    EXPECT_FALSE(cold.propagation.coarseStarted);
    EXPECT_EQ(cold.coarseStart.levels, 0);
    EXPECT_LT(started.propagation.stepsRun, cold.propagation.stepsRun);
    EXPECT_LT(d.mean, 4e-3);

    // A light nudge then starts from the last frame, not from the coarse grids.
    scene.lights[0].position += glm::dvec3(0.5, 0.0, 0.0);
    coarseStarted.setLights(scene.lights);
    RenderReport nudged;
    coarseStarted.render(scene.lpv, &nudged);
    EXPECT_TRUE(nudged.propagation.warmStarted);
    EXPECT_EQ(nudged.coarseStart.levels, 0);
    scene.lights[0].position -= glm::dvec3(0.5, 0.0, 0.0);
  }
}

TEST(CoarseStart, AStrokeResamplesTheCoarseGridsAsAFreshRendererWould) {
  // The coarse grids outlive frames; after a stroke they must hold the new material (a
  // stale coarse grid would still converge, to the right light, so the image alone could
  // hide it: the steps the coarse grids ran must equal a fresh renderer's too).
  Scene scene = pebbleScene();
  CpuRenderer renderer(scene);
  renderer.render(scene.lpv);
  const auto original = loadMaterialSet(*scene.material.vdb);
  auto painted = std::make_shared<MaterialSet>(*original);
  painted->sigmaS = openvdb::gridPtrCast<openvdb::Vec3SGrid>(original->sigmaS->deepCopyGrid());
  auto s = painted->sigmaS->getAccessor();
  const openvdb::CoordBBox block(openvdb::Coord(-4, 4, 8), openvdb::Coord(4, 12, 18));
  for (auto ijk = block.begin(); ijk; ++ijk) s.setValue(*ijk, s.getValue(*ijk) * 0.2f);
  Bounds everything;
  everything.extend(glm::dvec3(-1e6));
  everything.extend(glm::dvec3(1e6));
  renderer.setMaterialSet(painted, everything);
  RenderReport afterStroke, fresh;
  const Image strokeImage = renderer.render(scene.lpv, &afterStroke);
  CpuRenderer other(scene);
  other.setMaterialSet(painted, std::nullopt);
  const Image freshImage = other.render(scene.lpv, &fresh);
  EXPECT_TRUE(afterStroke.propagation.coarseStarted);
  EXPECT_EQ(afterStroke.coarseStart.steps, fresh.coarseStart.steps);
  EXPECT_EQ(afterStroke.propagation.stepsRun, fresh.propagation.stepsRun);
  EXPECT_LT(relativeDifference(strokeImage, freshImage).max, 1e-5);
}

}  // namespace

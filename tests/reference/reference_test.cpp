// The reference path tracer against closed forms. Every statistical check compares the
// Monte Carlo mean with the exact value within 4 standard errors of that same mean (a
// false failure about once in 16,000 runs with a fixed seed: never, since seeds are fixed)
// and also requires the standard error to be small against the value, so that a check
// cannot pass merely because the estimate is noisy.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "monte_carlo.h"
#include "seeded_draws.h"
#include "test_support.h"
#include "volume/core/image_io.h"
#include "volume/reference/majorant_grid.h"
#include "volume/material/material_field.h"
#include "volume/reference/reference_tracer.h"
#include "volume/scene/scene.h"

namespace sslpv::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A wide slab z in [0, kThickness] (mm), homogeneous base material on channel 0.
constexpr double kThickness = 0.2;
constexpr double kSigmaT = 1.0;
constexpr double kSigmaS = 0.5;
constexpr double kG = 0.5;
constexpr double kIrradiance = 3.0;

Scene slabScene(double ior, double sigmaS = kSigmaS) {
  const std::string json = R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-50, -50, 0], "max": [50, 50, )" +
                           std::to_string(kThickness) + R"(]},
    "material": {"base": {"sigma_t": [)" + std::to_string(kSigmaT) + R"(, 2, 3], "sigma_s": [)" +
                           std::to_string(sigmaS) + R"(, 1, 1], "g": )" + std::to_string(kG) +
                           R"(}, "ior": )" + std::to_string(ior) + R"(},
    "lights": [{"type": "directional", "direction": [0, 0, -1], "irradiance": [)" +
                           std::to_string(kIrradiance) + R"(, 1, 1]}],
    "camera": {"position": [0, 0, 100], "target": [0, 0, 0], "up": [0, 1, 0],
               "fov_y_deg": 0.5, "width": 1, "height": 1},
    "lpv": {"resolution": 8, "steps": 4, "shadow_map": 64}
  })";
  return parseScene(json, "slab.json");
}

/// A set whose only active voxel (σt 5, far from the z axis) raises the majorant to 5x
/// the base's, so the estimators along the axis go through null collisions: the answer
/// there must still be the homogeneous one.
std::shared_ptr<const MaterialSet> denseCornerSet() {
  auto set = emptyMaterialSet();
  set->sigmaT->tree().setValueOn(openvdb::Coord(40, 40, 0), openvdb::Vec3s(5.0f));
  set->sigmaS->tree().setValueOn(openvdb::Coord(40, 40, 0), openvdb::Vec3s(1.0f));
  return set;
}

/// `count` random active voxels with σt uniform in [lo, hi] per channel (σs = albedo·σt,
/// one value per voxel) within `radius` voxels of `centre`, on a grid of voxel size
/// `voxel` rotated by 0.5 rad about y (so bricks and voxels never line up).
std::shared_ptr<MaterialSet> randomBlobSet(int count, const openvdb::Coord& centre, int radius, double lo, double hi,
                                           double albedo, double voxel, std::uint64_t seed) {
  auto set = emptyMaterialSet();
  auto transform = openvdb::math::Transform::createLinearTransform(voxel);
  transform->postRotate(0.5, openvdb::math::Y_AXIS);
  set->sigmaT->setTransform(transform);
  set->sigmaS->setTransform(transform->copy());
  ReferenceRng rng(seed, 0, 0);
  for (int placed = 0; placed < count;) {
    openvdb::Coord ijk;
    for (int a = 0; a < 3; ++a) ijk[a] = centre[a] - radius + int(rng.uniform() * (2 * radius + 1));
    if ((ijk - centre).asVec3d().length() > radius) continue;
    openvdb::Vec3s t;
    for (int c = 0; c < 3; ++c) t[c] = float(lo + (hi - lo) * rng.uniform());
    set->sigmaT->tree().setValueOn(ijk, t);
    set->sigmaS->tree().setValueOn(ijk, t * float(albedo));
    ++placed;
  }
  return set;
}

/// Optical depth of channel c along the part of a -> b inside the box [lo, hi], by a
/// 4000-point midpoint rule on the field (piecewise cubic along a line: error ~1e-7).
double opticalDepth(const ReferenceTracer& tracer, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& lo,
                    const glm::dvec3& hi, int c) {
  const glm::dvec3 d = b - a;
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double u = (lo[k] - a[k]) / d[k], v = (hi[k] - a[k]) / d[k];
    t0 = std::max(t0, std::min(u, v));
    t1 = std::min(t1, std::max(u, v));
  }
  if (!(t0 < t1)) return 0.0;
  const MaterialField::Sampler field = tracer.field().sampler();
  constexpr int kSteps = 4000;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) sum += field.sample(a + (t0 + (t1 - t0) * (i + 0.5) / kSteps) * d).sigmaT[c];
  return sum * (t1 - t0) * glm::length(d) / kSteps;
}


void expectAgrees(const Estimate& e, double expected, double maxRelativeError, const char* what) {
  SCOPED_TRACE(what);
  EXPECT_LE(std::abs(e.mean - expected), 4.0 * e.standardError)
      << "mean " << e.mean << " expected " << expected << " standard error " << e.standardError;
  EXPECT_LE(e.standardError, maxRelativeError * expected) << "too noisy to check anything";
}

double hg(double cosTheta, double g) {
  return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * cosTheta, 1.5));
}

// Beer–Lambert: ratio tracking through the slab gives exp(-σt d) for each channel. With
// the global majorant (5, well above σt) the estimator goes through null collisions
// weighted by 1 - σt/σ̄; with per-brick majorants the axis only crosses bricks the set's
// voxel does not reach, where the tracer multiplies by exp(-σt·length) exactly: no
// variance, only float round-off of the hit distances.
TEST(ReferenceTracer, BeerLambertTransmittanceThroughAbsorbingSlab) {
  MajorantGridOptions global;
  global.global = true;
  const ReferenceTracer nullCollisions(slabScene(1.0, 0.0), denseCornerSet(), global);
  const ReferenceTracer bricks(slabScene(1.0, 0.0), denseCornerSet());
  EXPECT_DOUBLE_EQ(nullCollisions.majorant().x, 5.0);
  EXPECT_DOUBLE_EQ(bricks.majorant().x, 5.0);
  for (int c = 0; c < 3; ++c) {
    const double sigma = c == 0 ? kSigmaT : double(c + 1);
    const Estimate e = estimate(20000, [&](int i) {
      ReferenceRng rng(7, std::uint64_t(c), std::uint64_t(i));
      return nullCollisions.estimateTransmittance({0.1, -0.2, -10.0}, {0.1, -0.2, 10.0}, c, rng);
    });
    std::cout << "channel " << c << ": T = " << e.mean << " +- " << e.standardError << " (exact "
              << std::exp(-sigma * kThickness) << ")\n";
    expectAgrees(e, std::exp(-sigma * kThickness), 0.01, "transmittance, global majorant");
    ReferenceRng rng(7, 3, std::uint64_t(c));
    EXPECT_NEAR(bricks.estimateTransmittance({0.1, -0.2, -10.0}, {0.1, -0.2, 10.0}, c, rng),
                std::exp(-sigma * kThickness), 1e-6)
        << "homogeneous bricks are exact";
  }
}

// Through the trilinear footprint of the set's only voxel (centre (40, 40, 0), σt 5,
// voxel size 1) at x = 40.2, y = 40.1, the field is σ + (5 - σ)·0.8·0.9·(1 - z) in the
// slab, so τ = 0.2σ + (5 - σ)·0.72·0.18. The global majorant and the brick holding the
// footprint (while the slab's other bricks are homogeneous) must both give exp(-τ).
// Footprints across brick faces are BrickBoundsHoldTheFieldEverywhere's job.
TEST(ReferenceTracer, TransmittanceThroughAVoxelFootprintMatchesClosedForm) {
  MajorantGridOptions global;
  global.global = true;
  const ReferenceTracer withGlobal(slabScene(1.0, 0.0), denseCornerSet(), global);
  const ReferenceTracer withBricks(slabScene(1.0, 0.0), denseCornerSet());
  const glm::ivec3 dims = withBricks.majorantGrid().dims();
  EXPECT_GT(dims.x * dims.y, 100) << "the test needs bricks";
  EXPECT_TRUE(withBricks.majorantGrid().brickAt({0.1, -0.2, 0.1}).homogeneous);
  EXPECT_FALSE(withBricks.majorantGrid().brickAt({40.2, 40.1, 0.1}).homogeneous);
  for (int c = 0; c < 3; ++c) {
    const double sigma = c == 0 ? kSigmaT : double(c + 1);
    const double exact = std::exp(-(0.2 * sigma + (5.0 - sigma) * 0.72 * 0.18));
    for (const ReferenceTracer* tracer : {&withGlobal, &withBricks}) {
      const Estimate e = estimate(20000, [&](int i) {
        ReferenceRng rng(8, std::uint64_t(c), std::uint64_t(i));
        return tracer->estimateTransmittance({40.2, 40.1, -10.0}, {40.2, 40.1, 10.0}, c, rng);
      });
      std::cout << (tracer == &withGlobal ? "global" : "bricks") << " channel " << c << ": T = " << e.mean
                << " +- " << e.standardError << " (exact " << exact << ")\n";
      expectAgrees(e, exact, 0.01, tracer == &withGlobal ? "global majorant" : "brick majorants");
    }
  }
}

// Per-brick majorants and minorants bound the continuous field everywhere: at random
// points over the whole brick box and at points packed into every voxel's trilinear
// footprint (where bounds that counted only the voxels centred in a brick fail), with a
// rotated grid, a rotated and scaled object and σ in cm^-1 converted to mm^-1.
// Homogeneous bricks must see exactly the base material. The bricks must also be worth
// having: many of them homogeneous and well below the global majorant.
TEST(ReferenceTracer, BrickBoundsHoldTheFieldEverywhere) {
  const Scene scene = parseScene(R"({
    "units": "mm",
    "mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 10},
    "transform": {"translate": [3, -2, 1], "rotate_deg": [20, 35, 10], "scale": 1.5},
    "material": {"base": {"sigma_t": [1.0, 0.5, 0.2], "sigma_s": [0.5, 0.5, 0.1], "g": 0.0}},
    "lights": [{"type": "point", "position": [0, 0, 40], "intensity": [1, 1, 1]}],
    "camera": {"position": [0, 0, 60], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 30,
               "width": 4, "height": 4}
  })",
                                 "bound.json");
  auto set = randomBlobSet(600, openvdb::Coord(10, 0, 0), 12, 0.0, 40.0, 0.5, 0.5, 3);
  set->units = "cm";  // σ per cm: the field reads a tenth of the stored values per mm
  // An active tile (8^3 voxels) as well: its footprint is its box widened by one voxel.
  set->sigmaT->tree().addTile(1, openvdb::Coord(-16, 8, 0), openvdb::Vec3s(35.0f, 5.0f, 45.0f), true);
  const glm::dmat4 restToWorld = scene.transform.matrix();
  const openvdb::math::Transform& transform = set->sigmaT->constTransform();
  for (int voxelsPerBrick : {2, 8}) {
    SCOPED_TRACE(voxelsPerBrick);
    MajorantGridOptions options;
    options.voxelsPerBrick = voxelsPerBrick;
    const ReferenceTracer tracer(scene, set, options);
    const MajorantGrid& grid = tracer.majorantGrid();
    const MaterialField::Sampler field = tracer.field().sampler();
    const MaterialSample base = tracer.field().base();
    ReferenceRng rng(4, std::uint64_t(voxelsPerBrick), 0);
    std::size_t violations = 0, checked = 0, inHeterogeneous = 0;
    double tightest = 0.0;
    auto check = [&](const glm::dvec3& p) {
      const MajorantBrick& brick = grid.brickAt(p);
      const MaterialSample m = field.sample(p);
      ++checked;
      if (brick.homogeneous) {
        if (m.sigmaT != base.sigmaT || m.sigmaS != base.sigmaS || m.g != base.g) ++violations;
        if (brick.majorant != glm::dvec3(base.sigmaT) || brick.minorant != brick.majorant) ++violations;
        return;
      }
      ++inHeterogeneous;
      for (int c = 0; c < 3; ++c) {
        if (double(m.sigmaT[c]) > brick.majorant[c] || double(m.sigmaT[c]) < brick.minorant[c]) ++violations;
        tightest = std::max(tightest, double(m.sigmaT[c]) / brick.majorant[c]);
      }
    };
    const Bounds& box = grid.box();
    for (int i = 0; i < 100000; ++i)
      check(box.min + drawVec3<glm::dvec3>([&] { return rng.uniform(); }) * (box.max - box.min));
    for (auto it = set->sigmaT->cbeginValueOn(); it; ++it) {
      openvdb::CoordBBox voxels;
      it.getBoundingBox(voxels);
      for (int i = 0; i < 40; ++i) {
        openvdb::Vec3d index;
        for (int a = 0; a < 3; ++a)
          index[a] = voxels.min()[a] - 1.0 + (voxels.max()[a] - voxels.min()[a] + 2.0) * rng.uniform();
        const openvdb::Vec3d rest = transform.indexToWorld(index);
        check(glm::dvec3(restToWorld * glm::dvec4(rest[0], rest[1], rest[2], 1.0)));
      }
    }
    std::size_t homogeneous = 0, low = 0, bricks = 0;
    for (int z = 0; z < grid.dims().z; ++z)
      for (int y = 0; y < grid.dims().y; ++y)
        for (int x = 0; x < grid.dims().x; ++x) {
          const MajorantBrick& b = grid.brick(x, y, z);
          ++bricks;
          if (b.homogeneous) ++homogeneous;
          if (b.majorant.x < 0.5 * grid.globalMajorant().x) ++low;
        }
    std::cout << voxelsPerBrick << " voxels a brick: " << grid.dims().x << "x" << grid.dims().y << "x"
              << grid.dims().z << " bricks, " << homogeneous << " homogeneous, " << low
              << " below half the global majorant; " << checked << " points (" << inHeterogeneous
              << " in heterogeneous bricks), largest field/majorant " << tightest << "\n";
    EXPECT_EQ(violations, 0u);
    EXPECT_GT(inHeterogeneous, checked / 4) << "the footprint points must reach heterogeneous bricks";
    EXPECT_GT(tightest, 0.5) << "majorants far above the field everywhere would hide nothing";
    EXPECT_GT(homogeneous, bricks / 10);
    EXPECT_GT(low, bricks / 5);
    EXPECT_DOUBLE_EQ(grid.globalMajorant().z, 4.5);  // the tile's 45 per cm
  }
}

// Residual ratio tracking brick by brick is unbiased: along chords through a
// heterogeneous blob (random σt up to 3 over a thin base), the per-brick estimate and the
// plain ratio tracking of the global majorant both match exp(-τ) with τ integrated from
// the field itself.
TEST(ReferenceTracer, HeterogeneousTransmittanceAgreesAcrossMajorantsAndQuadrature) {
  Scene scene = slabScene(1.0, 0.0);
  scene.mesh.boxMin = glm::dvec3(-5.0);
  scene.mesh.boxMax = glm::dvec3(5.0);
  scene.material.base.sigmaT = glm::vec3(0.1f, 0.06f, 0.03f);
  scene.material.base.sigmaS = glm::vec3(0.0f);
  const auto set = randomBlobSet(120, openvdb::Coord(3, 0, 0), 5, 0.5, 3.0, 0.0, 0.25, 9);
  MajorantGridOptions globalOptions;
  globalOptions.global = true;
  const ReferenceTracer withGlobal(scene, set, globalOptions);
  const ReferenceTracer withBricks(scene, set);
  ReferenceRng chords(10, 0, 0);
  for (int k = 0; k < 6; ++k) {
    const double z = 1.0 - 2.0 * chords.uniform(), phi = 6.283185307179586 * chords.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const glm::dvec3 dir(r * std::cos(phi), r * std::sin(phi), z);
    const glm::dvec3 through =
        glm::dvec3(0.7, 0.0, -0.4) + 0.6 * drawVec3<glm::dvec3>([&] { return chords.uniform(); });
    const glm::dvec3 a = through - 20.0 * dir, b = through + 20.0 * dir;
    for (int c = 0; c < 3; ++c) {
      const double exact = std::exp(-opticalDepth(withBricks, a, b, glm::dvec3(-5.0), glm::dvec3(5.0), c));
      for (const ReferenceTracer* tracer : {&withGlobal, &withBricks}) {
        const Estimate e = estimate(8000, [&](int i) {
          ReferenceRng rng(11, std::uint64_t(k * 3 + c), std::uint64_t(i));
          return tracer->estimateTransmittance(a, b, c, rng);
        });
        std::cout << "chord " << k << (tracer == &withGlobal ? " global" : " bricks") << " channel " << c
                  << ": T = " << e.mean << " +- " << e.standardError << " (quadrature " << exact << ")\n";
        expectAgrees(e, exact, 0.05, tracer == &withGlobal ? "global majorant" : "brick majorants");
      }
    }
  }
}

// Single scattering seen along the slab normal, light along the normal (index-matched):
// backscatter L = E σs p(-1) (1 - exp(-2 σt d)) / (2 σt); from behind (forward scatter)
// L = E σs p(1) d exp(-σt d). Distinguishes g from -g (p(1)/p(-1) = 9 at g = 0.5).
TEST(ReferenceTracer, SingleScatteringMatchesClosedFormBothSides) {
  const ReferenceTracer tracer(slabScene(1.0), denseCornerSet());
  const double back = kIrradiance * kSigmaS * hg(-1.0, kG) * (1.0 - std::exp(-2.0 * kSigmaT * kThickness)) /
                      (2.0 * kSigmaT);
  const double forward = kIrradiance * kSigmaS * hg(1.0, kG) * kThickness * std::exp(-kSigmaT * kThickness);
  const Estimate eBack = estimate(400000, [&](int i) {
    ReferenceRng rng(11, 0, std::uint64_t(i));
    return tracer.radianceSample({0.0, 0.0, 100.0}, {0.0, 0.0, -1.0}, 0, rng, 1);
  });
  const Estimate eForward = estimate(400000, [&](int i) {
    ReferenceRng rng(12, 0, std::uint64_t(i));
    return tracer.radianceSample({0.0, 0.0, -100.0}, {0.0, 0.0, 1.0}, 0, rng, 1);
  });
  std::cout << "back " << eBack.mean << " +- " << eBack.standardError << " (exact " << back << "), forward "
            << eForward.mean << " +- " << eForward.standardError << " (exact " << forward << ")\n";
  expectAgrees(eBack, back, 0.02, "backscatter");
  expectAgrees(eForward, forward, 0.02, "forward scatter");
}

// The same backscatter with a dielectric boundary (η = 1.4) at normal incidence, where
// the light connection through the top face is a straight line: the camera ray
// enters with 1 - F and radiance / η², bounces between the faces with F (series
// 1/(1 - F² a²), a = exp(-σt d)), and every light connection crosses the top face once
// more with 1 - F. The light reaches depth z straight (exp(-σt z)), after a reflection off
// the bottom face (F exp(-σt (2d - z)), arriving from below) and after one more off the
// top face (F² exp(-σt (2d + z))): the tracer follows up to two internal reflections, and
// the first of them is a quarter of the answer. Integrated against the camera ray going
// down (exp(-σt z)) and going up after the bottom (F a exp(-σt (d - z))), the sum is
// down (1 + 2 F² a²) + 2 up + F³ a⁴ d p(0) with the `down` and `up` below. Checks the
// Fresnel and η² bookkeeping and the reflected connections.
TEST(ReferenceTracer, SingleScatteringThroughDielectricAtNormalIncidence) {
  const double eta = 1.4;
  const ReferenceTracer tracer(slabScene(eta));
  const double f = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  const double a = std::exp(-kSigmaT * kThickness);
  const double down = hg(-1.0, kG) * (1.0 - a * a) / (2.0 * kSigmaT);
  const double up = f * a * hg(1.0, kG) * kThickness * a;
  const double paths =
      down * (1.0 + 2.0 * f * f * a * a) + 2.0 * up + f * f * f * std::pow(a, 4.0) * kThickness * hg(1.0, kG);
  const double expected = (1.0 - f) / (eta * eta) * kIrradiance * kSigmaS * (1.0 - f) * paths / (1.0 - f * f * a * a);
  const Estimate e = estimate(400000, [&](int i) {
    ReferenceRng rng(13, 0, std::uint64_t(i));
    return tracer.radianceSample({0.0, 0.0, 100.0}, {0.0, 0.0, -1.0}, 0, rng, 1);
  });
  std::cout << "dielectric back " << e.mean << " +- " << e.standardError << " (exact " << expected << ")\n";
  expectAgrees(e, expected, 0.02, "dielectric backscatter");
}

// Single scattering in a thick slab (20 mean free paths) behind a dielectric face with
// the light 40° off the normal, seen along the normal: the light reaches depth z along the
// refracted direction θ2 with irradiance E (1 - F(θ1)) cos θ1 / cos θ2 across itself,
// attenuated by exp(-σt z / cos θ2); the camera ray enters with (1 - F(0)) / η². So
// L = (1 - F(0)) / η² · σs p(θ) E (1 - F(θ1)) (cos θ1 / cos θ2) / (σt (1 + 1 / cos θ2)),
// with θ the angle between the camera's direction and the way to the light inside.
// Checks the exact connection through the face (geometry, Fresnel, attenuation, phase).
TEST(ReferenceTracer, SingleScatteringThroughDielectricAtObliqueIncidence) {
  const double eta = 1.4, theta1 = 40.0 * kPi / 180.0;
  Scene scene = slabScene(eta);
  scene.mesh.boxMin.z = -20.0;
  scene.lights[0].direction = glm::dvec3(std::sin(theta1), 0.0, -std::cos(theta1));
  const ReferenceTracer tracer(scene);
  ASSERT_EQ(tracer.lightConnection(), ReferenceTracer::LightConnection::FlatFaces);
  const double cos1 = std::cos(theta1), sin2 = std::sin(theta1) / eta, cos2 = std::sqrt(1.0 - sin2 * sin2);
  const auto fresnel = [&](double cosI) {
    const double cosT = std::sqrt(1.0 - (1.0 - cosI * cosI) / (eta * eta));
    const double rs = (cosI - eta * cosT) / (cosI + eta * cosT), rp = (eta * cosI - cosT) / (eta * cosI + cosT);
    return 0.5 * (rs * rs + rp * rp);
  };
  const double phase = hg(-cos2, kG);  // camera travels along -z, the light is up along (-sin θ2, 0, cos θ2)
  const double expected = (1.0 - fresnel(1.0)) / (eta * eta) * kSigmaS * phase * kIrradiance *
                          (1.0 - fresnel(cos1)) * (cos1 / cos2) / (kSigmaT * (1.0 + 1.0 / cos2));
  const Estimate e = estimate(400000, [&](int i) {
    ReferenceRng rng(14, 0, std::uint64_t(i));
    return tracer.radianceSample({0.0, 0.0, 100.0}, {0.0, 0.0, -1.0}, 0, rng, 1);
  });
  std::cout << "oblique dielectric single scattering " << e.mean << " +- " << e.standardError << " (exact "
            << expected << ")\n";
  expectAgrees(e, expected, 0.02, "oblique dielectric single scattering");
}

/// White furnace with delta lights: in a non-absorbing, index-matched medium under
/// uniform incident radiance L0 the radiance is L0 everywhere. Uniform illumination is
/// sampled per group by `lights` directional lights in a Fibonacci spiral under a random
/// rotation, each with irradiance 4π L0 / lights (so their mean over rotations is the
/// uniform field; one light is a uniformly random direction). A camera ray never sees a
/// delta light directly, so what it gets is L0 minus the unscattered part,
/// L0 (1 - exp(-τ)), τ the optical depth of the chord along the camera axis (returned in
/// `tau`, integrated from the field). Multiple scattering, HG sampling against HG
/// evaluation in next-event estimation, free flights across brick faces and the null
/// collisions of heterogeneous bricks all enter. The camera looks down -z from `camera`.
Estimate furnace(double ior, std::shared_ptr<const MaterialSet> set, double l0, double sigmaT,
                 const MajorantGridOptions& majorants, double& tau, bool box = false, int groups = 320, int lights = 1,
                 glm::dvec3 camera = glm::dvec3(0.0, 0.0, 10.0)) {
  const int perGroup = 64;
  std::vector<double> means;
  ReferenceRng directions(99, 0, 0);
  const auto num = [](double v) { return std::to_string(v); };
  for (int k = 0; k < groups; ++k) {
    // Rotation by angle b about the axis (a, b) of a uniformly random direction, then a
    // random spin c of the spiral: a uniformly random rotation is not needed, only that
    // every direction be equally likely.
    const double a = 2.0 * kPi * directions.uniform(), b = std::acos(1.0 - 2.0 * directions.uniform());
    const double spin = 2.0 * kPi * directions.uniform();
    const glm::dvec3 axis(std::sin(b) * std::cos(a), std::sin(b) * std::sin(a), std::cos(b));
    std::string lightList;
    for (int i = 0; i < lights; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / lights, r = std::sqrt(1.0 - z * z), phi = i * 2.399963229728653 + spin;
      glm::dvec3 v(r * std::cos(phi), r * std::sin(phi), z);
      v = v * std::cos(b) + glm::cross(axis, v) * std::sin(b) + axis * glm::dot(axis, v) * (1.0 - std::cos(b));
      lightList += std::string(i ? "," : "") + R"({"type": "directional", "direction": [)" + num(v.x) + "," +
                   num(v.y) + "," + num(v.z) + R"(], "irradiance": [)" + num(4.0 * kPi * l0 / lights) + ", 1, 1]}";
    }
    const std::string s = num(sigmaT);
    const std::string json = R"({
      "units": "mm",
      "mesh": )" + std::string(box ? R"({"primitive": "box", "min": [-1, -1, -1], "max": [1, 1, 1]})"
                                    : R"({"primitive": "sphere", "center": [0, 0, 0], "radius": 1})") + R"(,
      "material": {"base": {"sigma_t": [)" + s + "," + s + "," + s + R"(], "sigma_s": [)" + s + "," + s +
                             "," + s + R"(], "g": 0.3}, "ior": )" + num(ior) + R"(},
      "lights": [)" + lightList + R"(],
      "camera": {"position": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 1,
                 "width": 1, "height": 1}
    })";
    const ReferenceTracer tracer(parseScene(json, "furnace.json"), set, majorants);
    if (k == 0)
      tau = opticalDepth(tracer, camera, camera - glm::dvec3(0.0, 0.0, 20.0), glm::dvec3(-1.0), glm::dvec3(1.0), 0);
    double sum = 0.0;
    for (int i = 0; i < perGroup; ++i) {
      ReferenceRng rng(21, std::uint64_t(k), std::uint64_t(i));
      sum += tracer.radianceSample(camera, {0.0, 0.0, -1.0}, 0, rng);
    }
    means.push_back(sum / perGroup);
  }
  return estimate(groups, [&](int k) { return means[std::size_t(k)]; });
}

TEST(ReferenceTracer, WhiteFurnaceIndexMatchedSphere) {
  const double l0 = 2.0, sigmaT = 2.0;
  // An albedo-1 blob (σt = σs from 3 to 6) around the centre in the σt = σs = 2 base,
  // with bricks of 2 voxels: homogeneous and heterogeneous bricks along every path.
  MajorantGridOptions options;
  options.voxelsPerBrick = 2;
  double tau = 0.0;
  const Estimate e = furnace(1.0, randomBlobSet(30, openvdb::Coord(0, 0, 0), 3, 3.0, 6.0, 1.0, 0.25, 5), l0, sigmaT,
                             options, tau);
  const double expected = l0 * (1.0 - std::exp(-tau));
  std::cout << "furnace " << e.mean << " +- " << e.standardError << " (exact " << expected << ", tau " << tau
            << ")\n";
  EXPECT_GT(tau, sigmaT * 2.0 + 0.3) << "the camera axis must cross the blob";
  expectAgrees(e, expected, 0.02, "white furnace");
}

// The white furnace through a dielectric box (η = 1.4, σt = 8: 16 mean free paths across):
// every light reaches the medium through a flat face, so the connections are exact, and
// the camera, looking at a face along its normal, sees (1 - F(0)) L0: everything but the
// environment's specular reflection, which delta lights cannot give. Once at the face's
// centre, once 0.1 (0.8 mean free paths) from two edges, where light refracted in through
// one face is totally reflected by the other before it scatters: without the reflected
// connections (refractedLight) the tracer was 1.9 % dark at the centre and 8.8 % there.
TEST(ReferenceTracer, WhiteFurnaceDielectricBoxWithExactConnections) {
  const double l0 = 2.0, sigmaT = 8.0, eta = 1.4;
  const double f0 = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  const double expected = (1.0 - f0) * l0;
  for (const glm::dvec3 camera : {glm::dvec3(0.0, 0.0, 10.0), glm::dvec3(0.9, 0.9, 10.0)}) {
    double tau = 0.0;
    const Estimate e = furnace(eta, nullptr, l0, sigmaT, MajorantGridOptions{}, tau, true, 300, 16, camera);
    std::cout << "dielectric box furnace, camera at x = y = " << camera.x << ": " << e.mean << " +- "
              << e.standardError << " (exact " << expected << ")\n";
    expectAgrees(e, expected, 0.02, "dielectric box furnace");
  }
  Scene box = slabScene(eta);
  EXPECT_EQ(ReferenceTracer(box).lightConnection(), ReferenceTracer::LightConnection::FlatFaces);
  box.mesh.kind = MeshSource::Kind::Sphere;
  box.mesh.center = glm::dvec3(0.0);
  box.mesh.radius = 5.0;
  EXPECT_EQ(ReferenceTracer(box).lightConnection(), ReferenceTracer::LightConnection::Faceted);
  box.material.ior = 1.0;
  EXPECT_EQ(ReferenceTracer(box).lightConnection(), ReferenceTracer::LightConnection::StraightLine)
      << "index-matched: straight is exact";
}

// The same through a curved boundary (a unit icosphere of 20480 faces), whose lights are
// connected through its faces (FacetedBoundary, connectionFaces). σt = 4: the camera's
// unscattered transmission through the sphere, which sees no environment here, is
// exp(-8) (0.03 %), and light reaching a vertex after an internal reflection crosses a
// chord of at least 1.4 (a sphere never reflects it totally): both below the noise. The
// straight-line connection this replaced was 12 % dark at σt = 2.
TEST(ReferenceTracer, WhiteFurnaceDielectricSphereWithFacetedConnections) {
  const double l0 = 2.0, sigmaT = 4.0, eta = 1.4;
  const double f0 = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  double tau = 0.0;
  const Estimate e = furnace(eta, nullptr, l0, sigmaT, MajorantGridOptions{}, tau, false, 300, 16);
  std::cout << "dielectric sphere furnace " << e.mean << " +- " << e.standardError << " (exact " << (1.0 - f0) * l0
            << ")\n";
  expectAgrees(e, (1.0 - f0) * l0, 0.02, "dielectric sphere furnace");
}

// A purely absorbing, index-matched object is invisible except for what it hides:
// the camera sees through it to the black background.
TEST(ReferenceTracer, PurelyAbsorbingIndexMatchedObjectRendersBlack) {
  Scene scene = slabScene(1.0, 0.0);
  scene.material.base.sigmaS = glm::vec3(0.0f);
  scene.camera.width = scene.camera.height = 4;
  ReferenceOptions options;
  options.spp = 16;
  const ReferenceResult r = ReferenceTracer(scene).render(options);
  for (const glm::vec3& p : r.radiance.pixels) EXPECT_EQ(p, glm::vec3(0.0f));
}

Scene scatteringBoxScene() {
  return parseScene(R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
    "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.3}, "ior": 1.3},
    "lights": [{"type": "point", "position": [20, 30, 40], "intensity": [1000, 1000, 1000]},
               {"type": "spot", "position": [-20, 0, 20], "direction": [0.7071, 0, -0.7071],
                "fov_deg": 30, "intensity": [500, 500, 500]}],
    "camera": {"position": [0, 10, 40], "target": [0, 0, 0], "up": [0, 1, 0],
               "fov_y_deg": 20, "width": 24, "height": 20},
    "lpv": {"resolution": 8, "steps": 4, "shadow_map": 64}
  })",
                    "box.json");
}

// Each pixel's samples use their own random stream, so the thread count and tile order
// cannot change a single bit; a different seed must change the image. Also with a
// heterogeneous set (brick traversal and null collisions).
TEST(ReferenceTracer, DeterministicForASeedRegardlessOfThreads) {
  for (const auto& set : {std::shared_ptr<const MaterialSet>(),
                          std::shared_ptr<const MaterialSet>(
                              randomBlobSet(100, openvdb::Coord(0, 0, 0), 8, 0.5, 4.0, 0.8, 0.25, 6))}) {
    SCOPED_TRACE(set ? "heterogeneous" : "homogeneous");
    const ReferenceTracer tracer(scatteringBoxScene(), set);
    ReferenceOptions options;
    options.spp = 4;
    options.seed = 5;
    options.threads = 1;
    const ReferenceResult one = tracer.render(options);
    options.threads = 2;
    const ReferenceResult two = tracer.render(options);
    options.seed = 6;
    const ReferenceResult other = tracer.render(options);
    ASSERT_EQ(one.radiance.pixels.size(), two.radiance.pixels.size());
    EXPECT_EQ(0, std::memcmp(one.radiance.pixels.data(), two.radiance.pixels.data(),
                             one.radiance.pixels.size() * sizeof(glm::vec3)));
    EXPECT_EQ(0, std::memcmp(one.standardError.pixels.data(), two.standardError.pixels.data(),
                             one.standardError.pixels.size() * sizeof(glm::vec3)));
    EXPECT_NE(0, std::memcmp(one.radiance.pixels.data(), other.radiance.pixels.data(),
                             one.radiance.pixels.size() * sizeof(glm::vec3)));
    double sum = 0.0;
    for (const glm::vec3& p : one.radiance.pixels) sum += p.x + p.y + p.z;
    EXPECT_GT(sum, 0.0) << "the lit box must show up";
  }
}

// The command line: bad flags are one-line input errors naming the flag, nothing written;
// a good run writes the image and its standard-error image.
TEST(ReferenceCommand, BadInputAndHappyPath) {
  TempDir dir;
  writeText(dir / "scene.json", R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
    "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.0}, "ior": 1.3},
    "lights": [{"type": "point", "position": [20, 30, 40], "intensity": [1000, 1000, 1000]}],
    "camera": {"position": [0, 10, 40], "target": [0, 0, 0], "up": [0, 1, 0],
               "fov_y_deg": 35, "width": 16, "height": 16},
    "lpv": {"resolution": 8, "steps": 4, "shadow_map": 64}
  })");
  const std::string scene = (dir / "scene.json").string();
  const std::string out = (dir / "out.exr").string();
  struct Case {
    std::vector<std::string> args;
    std::string mentions;
  };
  const std::vector<Case> cases = {
      {{"reference", scene, "-o", out, "--spp", "0"}, "--spp"},
      {{"reference", scene, "-o", out, "--spp", "-3"}, "--spp"},
      {{"reference", scene, "-o", out, "--spp", "4", "--threads", "-1"}, "--threads"},
      {{"reference", scene, "-o", (dir / "missing" / "out.exr").string(), "--spp", "4"}, "missing"},
      {{"reference", scene, "-o", (dir / "out.tiff").string(), "--spp", "4"}, "out.tiff"},
      {{"reference", (dir / "nope.json").string(), "-o", out, "--spp", "4"}, "nope.json"},
  };
  for (const Case& c : cases) {
    const RunResult r = runSslpv(c.args);
    SCOPED_TRACE(c.args.back());
    EXPECT_EQ(r.exitCode, 2) << r.stderrText;
    EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
    EXPECT_NE(r.stderrText.find("sslpv: error: "), std::string::npos) << r.stderrText;
    EXPECT_NE(r.stderrText.find(c.mentions), std::string::npos) << r.stderrText;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.stderr.exr"));

  const RunResult ok = runSslpv({"reference", scene, "-o", out, "--spp", "4", "--seed", "3", "--threads", "2"});
  ASSERT_EQ(ok.exitCode, 0) << ok.stderrText;
  // Not a terminal: one summary line instead of a progress line redrawn with '\r'.
  EXPECT_EQ(ok.stderrText.find('\r'), std::string::npos);
  EXPECT_EQ(ok.stderrText.rfind("reference: traced 4 spp at 16x16 (", 0), 0u) << ok.stderrText;
  const Image image = readImage(out);
  const Image error = readImage(dir / "out.stderr.exr");
  EXPECT_EQ(image.width, 16);
  EXPECT_EQ(error.width, 16);
  // Where the box is lit the estimate is positive and, at 4 spp, visibly noisy.
  bool litAndNoisy = false;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    EXPECT_TRUE(std::isfinite(error.pixels[i].x) && error.pixels[i].x >= 0.0f);
    if (image.pixels[i].x > 0.0f && error.pixels[i].x > 0.0f) litAndNoisy = true;
  }
  EXPECT_TRUE(litAndNoisy);
}

}  // namespace
}  // namespace sslpv::test

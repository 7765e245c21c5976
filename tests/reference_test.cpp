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

#include "test_support.h"
#include "volume/image_io.h"
#include "volume/reference_tracer.h"
#include "volume/scene.h"

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
  openvdb::initialize();
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaT->setName("sigma_t");
  set->sigmaS->setName("sigma_s");
  set->sigmaT->tree().setValueOn(openvdb::Coord(40, 40, 0), openvdb::Vec3s(5.0f));
  set->sigmaS->tree().setValueOn(openvdb::Coord(40, 40, 0), openvdb::Vec3s(1.0f));
  return set;
}

struct Estimate {
  double mean = 0.0;
  double standardError = 0.0;
};

template <typename F>
Estimate estimate(int n, F&& sample) {
  double sum = 0.0, sumSq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double v = sample(i);
    sum += v;
    sumSq += v * v;
  }
  Estimate e;
  e.mean = sum / n;
  e.standardError = std::sqrt(std::max(0.0, (sumSq - n * e.mean * e.mean) / (n - 1.0)) / n);
  return e;
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

// Beer–Lambert: ratio tracking through the slab gives exp(-σt d) for each channel, with
// the majorant well above σt (null collisions weighted by 1 - σt/σ̄).
TEST(ReferenceTracer, BeerLambertTransmittanceThroughAbsorbingSlab) {
  const ReferenceTracer tracer(slabScene(1.0, 0.0), denseCornerSet());
  EXPECT_DOUBLE_EQ(tracer.majorant().x, 5.0);
  for (int c = 0; c < 3; ++c) {
    const double sigma = c == 0 ? kSigmaT : double(c + 1);
    const Estimate e = estimate(20000, [&](int i) {
      ReferenceRng rng(7, std::uint64_t(c), std::uint64_t(i));
      return tracer.estimateTransmittance({0.1, -0.2, -10.0}, {0.1, -0.2, 10.0}, c, rng);
    });
    std::cout << "channel " << c << ": T = " << e.mean << " +- " << e.standardError << " (exact "
              << std::exp(-sigma * kThickness) << ")\n";
    expectAgrees(e, std::exp(-sigma * kThickness), 0.01, "transmittance");
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
// the straight-line light connection follows the true refracted path: the camera ray
// enters with 1 - F and radiance / η², bounces between the faces with F (series
// 1/(1 - F² a²), a = exp(-σt d)), and every light connection crosses the top face once
// more with 1 - F. This is the closed form of the paths the estimator samples; it checks
// the Fresnel and η² bookkeeping. Physically there is one more term of the size of `up`
// (the light beam reflected off the bottom face before it scatters), which no straight
// connection can reach: part of the approximation stated in reference_tracer.h.
TEST(ReferenceTracer, SingleScatteringThroughDielectricAtNormalIncidence) {
  const double eta = 1.4;
  const ReferenceTracer tracer(slabScene(eta));
  const double f = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
  const double a = std::exp(-kSigmaT * kThickness);
  const double down = hg(-1.0, kG) * (1.0 - a * a) / (2.0 * kSigmaT);
  const double up = f * a * hg(1.0, kG) * kThickness * a;
  const double expected =
      (1.0 - f) / (eta * eta) * kIrradiance * kSigmaS * (1.0 - f) * (down + up) / (1.0 - f * f * a * a);
  const Estimate e = estimate(400000, [&](int i) {
    ReferenceRng rng(13, 0, std::uint64_t(i));
    return tracer.radianceSample({0.0, 0.0, 100.0}, {0.0, 0.0, -1.0}, 0, rng, 1);
  });
  std::cout << "dielectric back " << e.mean << " +- " << e.standardError << " (exact " << expected << ")\n";
  expectAgrees(e, expected, 0.02, "dielectric backscatter");
}

/// White furnace with delta lights: in a non-absorbing, index-matched medium under
/// uniform incident radiance L0 the radiance is L0 everywhere. Uniform illumination is
/// sampled by one directional light per group, from a uniformly random direction with
/// irradiance 4π L0 (so its mean over directions is the uniform field). A camera ray never
/// sees a delta light directly, so what it gets is L0 minus the unscattered part,
/// L0 (1 - exp(-σt · chord)). Multiple scattering, HG sampling against HG evaluation in
/// next-event estimation and the null collisions of the majorant all enter.
Estimate furnace(double ior, std::shared_ptr<const MaterialSet> set, double l0, double sigmaT) {
  const int groups = 320, perGroup = 64;
  std::vector<double> means;
  ReferenceRng directions(99, 0, 0);
  for (int k = 0; k < groups; ++k) {
    const double z = 1.0 - 2.0 * directions.uniform();
    const double phi = 2.0 * kPi * directions.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const std::string s = std::to_string(sigmaT);
    const std::string json = R"({
      "units": "mm",
      "mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 1},
      "material": {"base": {"sigma_t": [)" + s + "," + s + "," + s + R"(], "sigma_s": [)" + s + "," + s +
                             "," + s + R"(], "g": 0.3}, "ior": )" + std::to_string(ior) + R"(},
      "lights": [{"type": "directional", "direction": [)" +
                             std::to_string(r * std::cos(phi)) + "," + std::to_string(r * std::sin(phi)) + "," +
                             std::to_string(z) + R"(], "irradiance": [)" + std::to_string(4.0 * kPi * l0) +
                             R"(, 1, 1]}],
      "camera": {"position": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 1,
                 "width": 1, "height": 1}
    })";
    const ReferenceTracer tracer(parseScene(json, "furnace.json"), set);
    double sum = 0.0;
    for (int i = 0; i < perGroup; ++i) {
      ReferenceRng rng(21, std::uint64_t(k), std::uint64_t(i));
      sum += tracer.radianceSample({0.0, 0.0, 10.0}, {0.0, 0.0, -1.0}, 0, rng);
    }
    means.push_back(sum / perGroup);
  }
  return estimate(groups, [&](int k) { return means[std::size_t(k)]; });
}

TEST(ReferenceTracer, WhiteFurnaceIndexMatchedSphere) {
  const double l0 = 2.0, sigmaT = 2.0;
  // The set's only voxel, at (40, 40, 0), is far outside the unit sphere: majorant 5, σt 2.
  const Estimate e = furnace(1.0, denseCornerSet(), l0, sigmaT);
  const double expected = l0 * (1.0 - std::exp(-sigmaT * 2.0));
  std::cout << "furnace " << e.mean << " +- " << e.standardError << " (exact " << expected << ")\n";
  expectAgrees(e, expected, 0.02, "white furnace");
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
// cannot change a single bit; a different seed must change the image.
TEST(ReferenceTracer, DeterministicForASeedRegardlessOfThreads) {
  const ReferenceTracer tracer(scatteringBoxScene());
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
      {{"reference", scene, "-o", (dir / "out.png").string(), "--spp", "4"}, "out.png"},
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
  EXPECT_NE(ok.stderrText.find("ETA"), std::string::npos);
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

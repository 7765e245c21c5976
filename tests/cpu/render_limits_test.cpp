// `sslpv render` at the edges of what it can do: every image it writes is finite, a grid
// too small to hold the object is refused, a mesh wound inward or partly reversed renders
// as the outward one (with a warning), and the memory it needs is estimated from the
// arrays it really allocates and refused up front when the machine cannot give it.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <spawn.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.h"
#include "volume/core/image_io.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

extern char** environ;

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A 15 mm sphere of skin under a spot and a point light, seen by a 32x32 camera.
json sphereScene() {
  return json::parse(R"({
    "units": "mm",
    "mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 15},
    "material": {"base": {"preset": "skin1"}, "ior": 1.4},
    "lights": [
      {"type": "spot", "position": [-60, 60, 50], "direction": [0.609208, -0.609208, -0.507673],
       "fov_deg": 30, "intensity": [16000, 15500, 15000]},
      {"type": "point", "position": [40, -10, -50], "intensity": [5000, 4800, 4500]}],
    "camera": {"position": [0, 15, 63], "target": [0, 0, 0], "fov_y_deg": 35, "width": 32, "height": 32},
    "lpv": {"resolution": 16, "steps": "auto", "shadow_map": 64}
  })");
}

/// Renders `scene` (written into `dir`) with the backend and extra flags.
RunResult render(const TempDir& dir, const json& scene, const std::string& output, const std::string& backend,
                 std::vector<std::string> extra = {}) {
  writeText(dir / "scene.json", scene.dump());
  std::vector<std::string> args = {"render", (dir / "scene.json").string(), "-o", (dir / output).string(),
                                   "--backend", backend};
  args.insert(args.end(), extra.begin(), extra.end());
  return runSslpv(args);
}

/// Why the Vulkan backend cannot run here ("" when it can): exit 3 names the device.
std::string vulkanUnavailable(const RunResult& run) {
  return run.exitCode == 3 && run.stderrText.find("--backend vulkan") != std::string::npos ? run.stderrText : "";
}

double meanRadiance(const Image& image) {
  double sum = 0.0;
  for (const glm::vec3& p : image.pixels) sum += double(p.x) + double(p.y) + double(p.z);
  return sum / (3.0 * double(image.pixels.size()));
}

bool allFinite(const Image& image) {
  for (const glm::vec3& p : image.pixels)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  return true;
}

// Irradiance near the float range overflowed to Inf pixels and exited 0. The scene's range
// check now refuses it at its key (within the ranges nothing overflows; the renderers'
// finite-image check stays behind it), and nothing is written, on either backend.
TEST(RenderLimits, OverflowingRadianceFailsNamingTheSceneOnEitherBackend) {
  json scene = sphereScene();
  scene["lights"] = json::parse(R"([{"type": "directional", "direction": [0, -1, 0], "irradiance": [3.5e38, 1, 1]}])");
  for (const std::string backend : {"cpu", "vulkan"}) {
    TempDir dir;
    const RunResult run = render(dir, scene, "out.pfm", backend);
    if (backend == "vulkan" && !vulkanUnavailable(run).empty()) {
      std::cerr << "SKIPPED the vulkan half: " << run.stderrText;
      continue;
    }
    EXPECT_EQ(run.exitCode, 2) << backend << ": " << run.stderrText;
    EXPECT_NE(run.stderrText.find((dir / "scene.json").string() + ": lights[0].irradiance[0]: must be in"),
              std::string::npos)
        << run.stderrText;
    EXPECT_FALSE(fs::exists(dir / "out.pfm")) << backend;
  }
}

// Vulkan's single-scattering term multiplied two extinctions in float (NaN pixels at
// sigma_t = 3.4e38, which the scene's range now refuses); media up to the largest accepted
// sigma_t must render finite and agree with the CPU.
TEST(RenderLimits, DenseMediaRenderFiniteAndAlikeOnBothBackends) {
  for (const double sigma : {1e3, 1e6}) {
    json scene = sphereScene();
    scene["material"]["base"] = {{"sigma_t", {sigma, sigma, sigma}}, {"sigma_s", {0.5 * sigma, 0.5 * sigma, sigma}}};
    TempDir dir;
    const RunResult cpu = render(dir, scene, "cpu.pfm", "cpu");
    ASSERT_EQ(cpu.exitCode, 0) << cpu.stderrText;
    const RunResult vk = render(dir, scene, "vk.pfm", "vulkan");
    if (const std::string why = vulkanUnavailable(vk); !why.empty()) GTEST_SKIP() << "no Vulkan device: " << why;
    ASSERT_EQ(vk.exitCode, 0) << "sigma_t " << sigma << ": " << vk.stderrText;
    const Image a = readImage(dir / "cpu.pfm"), b = readImage(dir / "vk.pfm");
    ASSERT_TRUE(allFinite(a) && allFinite(b));
    EXPECT_GT(meanRadiance(a), 0.0);
    EXPECT_NEAR(meanRadiance(b), meanRadiance(a), 0.02 * meanRadiance(a)) << "sigma_t " << sigma;
  }
}

// At --grid 2 the object lay in the margin cells only and every pixel was black (exit 0).
TEST(RenderLimits, AGridTooSmallForTheObjectIsRefusedAndTheSmallestOneRenders) {
  TempDir dir;
  const RunResult two = render(dir, sphereScene(), "two.pfm", "cpu", {"--grid", "2"});
  EXPECT_EQ(two.exitCode, 2) << two.stderrText;
  EXPECT_NE(two.stderrText.find("--grid / lpv.resolution: must be at least 3"), std::string::npos) << two.stderrText;
  EXPECT_FALSE(fs::exists(dir / "two.pfm"));
  json scene = sphereScene();
  scene["lpv"]["resolution"] = 2;
  const RunResult key = render(dir, scene, "key.pfm", "cpu");
  EXPECT_EQ(key.exitCode, 2) << key.stderrText;
  EXPECT_NE(key.stderrText.find("lpv.resolution"), std::string::npos) << key.stderrText;
  const RunResult three = render(dir, sphereScene(), "three.pfm", "cpu", {"--grid", "3"});
  ASSERT_EQ(three.exitCode, 0) << three.stderrText;
  EXPECT_GT(meanRadiance(readImage(dir / "three.pfm")), 0.0);
}

/// A 20 mm cube as OBJ, outward, with the faces listed in `reversed` wound the other way.
void writeCube(const fs::path& file, const std::vector<int>& reversed) {
  std::ofstream out(file);
  for (int i = 0; i < 8; ++i) out << "v " << (i & 1 ? 10 : -10) << ' ' << (i & 2 ? 10 : -10) << ' ' << (i & 4 ? 10 : -10) << '\n';
  // Outward quads (1-based corners), two triangles each.
  const int quads[6][4] = {{1, 5, 7, 3}, {2, 4, 8, 6}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 3, 4, 2}, {5, 6, 8, 7}};
  for (int q = 0; q < 6; ++q) {
    const int* c = quads[q];
    const bool flip = std::find(reversed.begin(), reversed.end(), q) != reversed.end();
    for (const auto& t : {std::array<int, 3>{c[0], c[1], c[2]}, std::array<int, 3>{c[0], c[2], c[3]}})
      out << "f " << t[0] << ' ' << (flip ? t[2] : t[1]) << ' ' << (flip ? t[1] : t[2]) << '\n';
  }
}

// A closed mesh wound inward rendered black, and one reversed face of six made a box 35 %
// darker, silently: both are reoriented at load, with a one-line warning naming the mesh,
// and render exactly as the outward cube.
TEST(RenderLimits, InwardOrPartlyReversedMeshesRenderAsTheOutwardOneWithAWarning) {
  TempDir dir;
  writeCube(dir / "outward.obj", {});
  writeCube(dir / "inward.obj", {0, 1, 2, 3, 4, 5});
  writeCube(dir / "one_face.obj", {3});
  json scene = sphereScene();
  scene["camera"]["position"] = {0, 30, 70};
  std::map<std::string, Image> images;
  for (const std::string name : {"outward", "inward", "one_face"}) {
    scene["mesh"] = {{"path", (dir / (name + ".obj")).string()}};
    const RunResult run = render(dir, scene, name + ".pfm", "cpu");
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    const std::string warning = "sslpv: warning: " + (dir / (name + ".obj")).string() + ": ";
    if (name == "outward") {
      EXPECT_EQ(run.stderrText, "");
    } else {
      EXPECT_EQ(run.stderrText.rfind(warning, 0), 0u) << run.stderrText;
      EXPECT_NE(run.stderrText.find(name == "inward" ? "12 of 12 triangles" : "2 of 12 triangles"), std::string::npos)
          << run.stderrText;
      EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    }
    images[name] = readImage(dir / (name + ".pfm"));
  }
  ASSERT_GT(meanRadiance(images["outward"]), 0.0);
  EXPECT_EQ(images["inward"].pixels, images["outward"].pixels);
  EXPECT_EQ(images["one_face"].pixels, images["outward"].pixels);
}

// An optically thin sphere (albedo 0.9) was ~10^4 times too bright at 2e-5 mean free paths
// across and twice too bright at 0.2: all entering light was taken to diffuse, and the
// single-scattering term's samples fell beyond the object. Now the render warns, naming
// the optical thickness, and stays within a factor of 2 of the path tracer (measured
// x0.55 and x0.59 here; not wildly wrong, not accurate either, as the warning says).
TEST(RenderLimits, OpticallyThinObjectsWarnAndStayNearThePathTracer) {
  // (At 1e-6 the path tracer's 16 spp of 32x32 pixels scatter about once in all, too few
  // to compare with: measured at 64x64 it went from x8876 to x0.48.)
  for (const double sigma : {1e-3, 1e-2}) {
    json scene = sphereScene();
    scene["material"]["base"] = {{"sigma_t", {sigma, sigma, sigma}},
                                 {"sigma_s", {0.9 * sigma, 0.9 * sigma, 0.9 * sigma}},
                                 {"g", 0}};
    TempDir dir;
    const RunResult run = render(dir, scene, "lpv.pfm", "cpu");
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_NE(run.stderrText.find("the object is optically thin ("), std::string::npos) << run.stderrText;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    const RunResult reference = runSslpv({"reference", (dir / "scene.json").string(), "-o",
                                          (dir / "reference.exr").string(), "--spp", "16", "--threads", "2"});
    ASSERT_EQ(reference.exitCode, 0) << reference.stderrText;
    const double ratio = meanRadiance(readImage(dir / "lpv.pfm")) / meanRadiance(readImage(dir / "reference.exr"));
    std::printf("sigma_t %g: mean radiance x%.3f of the path tracer\n", sigma, ratio);
    EXPECT_GT(ratio, 0.4) << "sigma_t " << sigma;
    EXPECT_LT(ratio, 2.0) << "sigma_t " << sigma;
  }
  // A thick object (30 mean free paths across) is not warned about.
  json scene = sphereScene();
  scene["material"]["base"] = {{"sigma_t", {1, 1, 1}}, {"sigma_s", {0.9, 0.9, 0.9}}, {"g", 0}};
  TempDir dir;
  const RunResult thick = render(dir, scene, "lpv.pfm", "cpu");
  ASSERT_EQ(thick.exitCode, 0) << thick.stderrText;
  EXPECT_EQ(thick.stderrText, "");
}

/// Peak resident memory of `sslpv args...` in KiB, from wait4's rusage of that child.
long peakRssKib(const std::vector<std::string>& args, int* exitCode) {
  std::vector<std::string> command = {SSLPV_BINARY};
  command.insert(command.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : command) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) return -1;
  *exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return usage.ru_maxrss;
}

// The check used to assume ~200 B a cell where ~370 B are allocated, so a grid that could
// not fit passed it and grew past the machine's memory. The estimate is now the sum of
// the arrays the CPU backend holds while it propagates; its growth from a small grid to
// grids of 64^3 and 128^3 cells must match the measured growth of the peak RSS.
TEST(RenderLimits, TheCpuMemoryEstimateMatchesThePeakResidentMemory) {
  TempDir dir;
  writeText(dir / "scene.json", sphereScene().dump());
  MeshSource sphere;
  sphere.kind = MeshSource::Kind::Sphere;
  sphere.center = glm::dvec3(0.0);
  sphere.radius = 15.0;
  const Bounds bounds = loadMesh(sphere, Transform{}).bounds();
  const auto measure = [&](int grid) {
    int exitCode = -1;
    const long kib = peakRssKib({"render", (dir / "scene.json").string(), "-o", (dir / "out.pfm").string(),
                                 "--backend", "cpu", "--grid", std::to_string(grid)},
                                &exitCode);
    EXPECT_EQ(exitCode, 0) << "--grid " << grid;
    return std::pair<double, double>(double(kib) * 1024.0, double(estimateLpvBytes(makeGridFrame(bounds, grid))));
  };
  const auto [baseRss, baseEstimate] = measure(8);
  for (const int grid : {64, 128}) {
    const auto [rss, estimate] = measure(grid);
    const double grown = rss - baseRss, predicted = estimate - baseEstimate;
    EXPECT_GT(predicted, 0.7 * grown) << "--grid " << grid << ": measured " << grown / 1048576 << " MiB";
    EXPECT_LT(predicted, 1.3 * grown) << "--grid " << grid << ": measured " << grown / 1048576 << " MiB";
  }
}

// A grid whose estimate exceeds the available memory is refused with the estimate
// (exit 3) before anything is allocated, rather than growing until the machine gives out.
TEST(RenderLimits, AGridThatCannotFitIsRefusedWithItsEstimate) {
  MeshSource sphere;
  sphere.kind = MeshSource::Kind::Sphere;
  sphere.center = glm::dvec3(0.0);
  sphere.radius = 15.0;
  const GridFrame frame = makeGridFrame(loadMesh(sphere, Transform{}).bounds(), 512);
  if (estimateLpvBytes(frame) <= availableMemoryBytes())
    GTEST_SKIP() << "this machine has " << (availableMemoryBytes() >> 30) << " GiB available: grid 512 would fit";
  TempDir dir;
  const RunResult run = render(dir, sphereScene(), "out.pfm", "cpu", {"--grid", "512"});
  EXPECT_EQ(run.exitCode, 3) << run.stderrText;
  EXPECT_NE(run.stderrText.find("cells needs about " + std::to_string(estimateLpvBytes(frame) >> 20) + " MiB"),
            std::string::npos)
      << run.stderrText;
  EXPECT_FALSE(fs::exists(dir / "out.pfm"));
}

}  // namespace
}  // namespace sslpv::test

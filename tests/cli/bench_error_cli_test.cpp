// End-to-end tests of `sslpv bench-error` on a tiny scene (32x32 box, CPU backend): the
// tables hold one row per configuration with plausible numbers, the reference is path
// traced once and reused (the second run is faster, says "reused" and leaves the cached
// file alone), a corrupt cache file is re-rendered, bad input exits 2 with one line and
// no output, and a missing plot exits 3 after writing the tables. The plot itself is
// checked by running sslpv-plot on a hand-made table (under xvfb-run without DISPLAY).

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"
#include "volume/core/image_io.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

/// Small enough that a sweep of it takes about a second.
const char* kScene = R"({
  "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
  "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.0}},
  "lights": [{"type": "point", "position": [20, 30, 40], "intensity": [1000, 1000, 1000]}],
  "camera": {"position": [0, 10, 40], "target": [0, 0, 0], "up": [0, 1, 0],
             "fov_y_deg": 35, "width": 32, "height": 32}
})";

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

std::optional<fs::path> findInPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (::access((fs::path(dir) / name).c_str(), X_OK) == 0) return fs::path(dir) / name;
  return std::nullopt;
}

bool haveDisplay() {
  const char* d = std::getenv("DISPLAY");
  return d && *d;
}

/// Why no plot can be drawn here, or empty when one can.
std::string plotUnavailable() {
#ifndef SSLPV_PLOT_BINARY
  return "this build has no sslpv-plot (VTK not found at configure time)";
#else
  if (!haveDisplay() && !findInPath("xvfb-run")) return "neither DISPLAY nor xvfb-run (apt-get install xvfb xauth)";
  return {};
#endif
}

/// Sets (or unsets, with nullptr) an environment variable for the life of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    value ? ::setenv(name, value, 1) : ::unsetenv(name);
  }
  ~ScopedEnv() { old_ ? ::setenv(name_.c_str(), old_->c_str(), 1) : ::unsetenv(name_.c_str()); }

 private:
  std::string name_;
  std::optional<std::string> old_;
};

class BenchErrorCli : public ::testing::Test {
 protected:
  void SetUp() override { writeText(scene(), kScene); }
  fs::path scene() const { return dir_ / "box.json"; }
  fs::path cache() const { return dir_ / "cache"; }
  fs::path prefix() const { return dir_ / "out"; }
  std::vector<std::string> sweep(const std::string& spp = "16") const {
    return {"bench-error", scene().string(), "--grid", "4,8",   "--steps", "2,auto",  "--backend",
            "cpu",         "--spp",          spp,     "--repeats", "1", "--cache", cache().string(),
            "-o",          prefix().string()};
  }
  std::vector<fs::path> cachedExrs() const {
    std::vector<fs::path> files;
    if (fs::exists(cache()))
      for (const auto& e : fs::directory_iterator(cache()))
        if (e.path().extension() == ".exr") files.push_back(e.path());
    return files;
  }
  /// Runs the sweep; the plot's outcome depends on this machine, the tables' must not.
  RunResult runSweep(const std::string& spp = "16", double* seconds = nullptr) const {
    const auto start = Clock::now();
    RunResult r = runSslpv(sweep(spp));
    if (seconds) *seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (plotUnavailable().empty()) {
      EXPECT_EQ(r.exitCode, 0) << r.stderrText;
      EXPECT_TRUE(fs::exists(prefix().string() + ".png"));
    } else {
      EXPECT_EQ(r.exitCode, 3) << r.stderrText;
      EXPECT_NE(r.stderrText.find("plot not written"), std::string::npos) << r.stderrText;
    }
    return r;
  }
  TempDir dir_;
};

TEST_F(BenchErrorCli, WritesOneRowPerConfigurationAndReusesTheReference) {
  // 1024 spp: a reference of a few seconds, so reusing it shows in the wall time.
  double firstSeconds = 0, secondSeconds = 0;
  const RunResult first = runSweep("1024", &firstSeconds);
  EXPECT_NE(first.stdoutText.find("reference " + scene().string() + ": rendered"), std::string::npos)
      << first.stdoutText;
  ASSERT_EQ(cachedExrs().size(), 1u);
  const fs::path exr = cachedExrs()[0];
  fs::path sidecar = exr;
  sidecar.replace_extension(".json");
  const json side = json::parse(readText(sidecar));
  EXPECT_EQ(side.at("spp"), 1024);
  EXPECT_EQ(side.at("scene"), scene().string());
  const double referenceSeconds = side.at("seconds").get<double>();

  // 2 schemes x 2 grids x 2 step settings on one backend.
  const std::vector<std::string> csv = lines(readText(prefix().string() + ".csv"));
  ASSERT_EQ(csv.size(), 1u + 8u);
  EXPECT_EQ(csv[0].rfind("scene,backend,scheme,grid,steps_requested,steps_run,shadow_map,", 0), 0u) << csv[0];
  const json table = json::parse(readText(prefix().string() + ".json"));
  ASSERT_EQ(table.at("rows").size(), 8u);
  EXPECT_EQ(table.at("references").at(0).at("status"), "rendered");
  int pareto = 0;
  std::set<std::string> configs;
  for (const json& row : table.at("rows")) {
    configs.insert(row.at("scheme").get<std::string>() + std::to_string(row.at("grid").get<int>()) +
                   row.at("steps_requested").get<std::string>());
    EXPECT_EQ(row.at("backend"), "cpu");
    if (row.at("steps_requested") == "2") {
      EXPECT_EQ(row.at("steps_run"), 2);
    }
    // auto stops when a step adds < 0.1 % of the power: more than 2 steps on 4-8 cells.
    if (row.at("steps_requested") == "auto") {
      EXPECT_GT(row.at("steps_run").get<int>(), 2);
    }
    EXPECT_GT(row.at("total_ms").get<double>(), 0.0);
    EXPECT_GE(row.at("total_ms").get<double>(), row.at("propagation_ms").get<double>());
    // Every metric was computed (JSON null would mean NaN). No accuracy bound here: a
    // 4-cell LPV is a stress case, not a preview setting.
    for (const char* key : {"relative_mse", "mean_relative_error", "rmse", "mean_ratio"})
      EXPECT_GT(row.at(key).get<double>(), 0.0) << key;
    EXPECT_LE(row.at("ssim").get<double>(), 1.0);
    EXPECT_GE(row.at("ssim").get<double>(), -1.0);
    pareto += row.at("pareto").get<bool>();
  }
  EXPECT_EQ(configs.size(), 8u);
  EXPECT_GE(pareto, 1);

  // Second run: the cached reference is read, not traced again.
  const auto exrTime = fs::last_write_time(exr);
  const RunResult second = runSweep("1024", &secondSeconds);
  EXPECT_NE(second.stdoutText.find("reference " + scene().string() + ": reused"), std::string::npos)
      << second.stdoutText;
  EXPECT_EQ(second.stderrText.find("path tracing"), std::string::npos) << second.stderrText;
  EXPECT_EQ(fs::last_write_time(exr), exrTime);
  EXPECT_EQ(cachedExrs().size(), 1u);
  EXPECT_EQ(json::parse(readText(prefix().string() + ".json")).at("references").at(0).at("status"), "reused");
  EXPECT_LT(secondSeconds, firstSeconds - 0.5 * referenceSeconds)
      << "first " << firstSeconds << " s, second " << secondSeconds << " s, reference " << referenceSeconds << " s";
  // Same reference, deterministic CPU renders: the errors repeat exactly.
  const json again = json::parse(readText(prefix().string() + ".json"));
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_EQ(again.at("rows").at(i).at("mean_relative_error"), table.at("rows").at(i).at("mean_relative_error"));
}

TEST_F(BenchErrorCli, CorruptCacheFileIsRenderedAgain) {
  runSweep();
  ASSERT_EQ(cachedExrs().size(), 1u);
  const fs::path exr = cachedExrs()[0];
  fs::path sidecar = exr;
  sidecar.replace_extension(".json");
  const std::string bytes = readText(exr), side = readText(sidecar);
  // Truncated (a full disk), one flipped bit that may still decode, a damaged sidecar.
  std::string flipped = bytes;
  flipped[flipped.size() - 10] ^= 1;
  const std::vector<std::pair<std::string, std::string>> damage = {
      {bytes.substr(0, bytes.size() / 2), side}, {flipped, side}, {bytes, side.substr(0, side.size() / 2)}};
  for (const auto& [exrBytes, sideBytes] : damage) {
    writeText(exr, exrBytes);
    writeText(sidecar, sideBytes);
    const RunResult r = runSweep();
    EXPECT_NE(r.stderrText.find("is unusable"), std::string::npos) << r.stderrText;
    EXPECT_NE(r.stdoutText.find(": rendered"), std::string::npos) << r.stdoutText;
    EXPECT_EQ(readText(exr), bytes) << "the same scene, spp and seed trace the same image";
    // The sidecar records the trace's wall time, so compare everything but that.
    json written = json::parse(readText(sidecar)), expected = json::parse(side);
    written.erase("seconds");
    expected.erase("seconds");
    EXPECT_EQ(written, expected);
  }
}

TEST_F(BenchErrorCli, BadInputExitsTwoWithOneLineAndNoOutput) {
  const std::string preexisting = "an older table a failed run must leave alone\n";
  writeText(prefix().string() + ".csv", preexisting);
  struct Case {
    std::string option, value, mention;
  };
  const std::vector<Case> cases = {
      {"--backend", "cpu,metal", "--backend: unknown value 'metal'"},
      {"--grid", "32,,64", "--grid: empty item"},
      {"--grid", "1", "--grid: '1'"},
      {"--steps", "0", "--steps: '0'"},
      {"--scheme", "best", "--scheme: unknown value 'best'"},
      {"--block", "0", "--block"},
      {"scene", (dir_ / "missing.json").string(), "missing.json"},
      {"-o", (dir_ / "no-such-dir" / "out").string(), "no-such-dir"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = sweep();
    if (c.option == "scene") {
      args[1] = c.value;
    } else {
      const auto it = std::find(args.begin(), args.end(), c.option);
      if (it != args.end())
        *(it + 1) = c.value;
      else
        args.insert(args.end(), {c.option, c.value});
    }
    const RunResult r = runSslpv(args);
    EXPECT_EQ(r.exitCode, 2) << c.option << " " << c.value << ": " << r.stderrText;
    const std::vector<std::string> err = lines(r.stderrText);
    ASSERT_EQ(err.size(), 1u) << c.option << " " << c.value << ": " << r.stderrText;
    EXPECT_EQ(err[0].rfind("sslpv: error: ", 0), 0u) << err[0];
    EXPECT_NE(err[0].find(c.mention), std::string::npos) << err[0];
    EXPECT_EQ(readText(prefix().string() + ".csv"), preexisting);
    EXPECT_FALSE(fs::exists(prefix().string() + ".json"));
    EXPECT_TRUE(cachedExrs().empty()) << "no reference may be traced before the input is checked";
  }
}

TEST_F(BenchErrorCli, WithoutADisplayOrXvfbTheTablesAreWrittenAndTheExitIsThree) {
  // An empty PATH hides xvfb-run; sslpv itself is started by absolute path.
  const fs::path empty = dir_ / "empty-bin";
  fs::create_directory(empty);
  writeText(prefix().string() + ".png", "a plot of an older run\n");
  ScopedEnv display("DISPLAY", nullptr);
  ScopedEnv path("PATH", empty.c_str());
  const RunResult r = runSslpv(sweep());
  EXPECT_EQ(r.exitCode, 3) << r.stderrText;
  const std::vector<std::string> err = lines(r.stderrText);
  ASSERT_FALSE(err.empty());
  EXPECT_EQ(err.back().rfind("sslpv: error: plot not written: ", 0), 0u) << err.back();
  EXPECT_EQ(lines(readText(prefix().string() + ".csv")).size(), 9u);
  EXPECT_EQ(json::parse(readText(prefix().string() + ".json")).at("rows").size(), 8u);
  EXPECT_FALSE(fs::exists(prefix().string() + ".png")) << "a stale plot would pass for this run's";
}

TEST_F(BenchErrorCli, WithoutAVulkanDeviceTheVulkanConfigurationsAreSkippedLoudly) {
  // No ICD file: the Vulkan loader finds no device at all (lavapipe hidden).
  ScopedEnv icd("VK_ICD_FILENAMES", (dir_ / "none.json").c_str());
  ScopedEnv drivers("VK_DRIVER_FILES", (dir_ / "none.json").c_str());
  std::vector<std::string> args = sweep();
  *(std::find(args.begin(), args.end(), "--backend") + 1) = "cpu,vulkan";
  const RunResult r = runSslpv(args);
  EXPECT_TRUE(r.exitCode == 0 || r.exitCode == 3) << r.stderrText;  // 3: no plot here
  EXPECT_NE(r.stderrText.find("bench-error: WARNING: skipped the 8 vulkan configurations: "), std::string::npos)
      << r.stderrText;
  const json table = json::parse(readText(prefix().string() + ".json"));
  ASSERT_EQ(table.at("rows").size(), 8u);
  for (const json& row : table.at("rows")) EXPECT_EQ(row.at("backend"), "cpu");
  ASSERT_EQ(table.at("skipped").size(), 1u);

  // Nothing but vulkan asked for: nothing to run is a resource problem, exit 3.
  *(std::find(args.begin(), args.end(), "--backend") + 1) = "vulkan";
  const RunResult only = runSslpv(args);
  EXPECT_EQ(only.exitCode, 3) << only.stderrText;
  EXPECT_NE(only.stderrText.find("sslpv: error: --backend: nothing left to run without a Vulkan device"),
            std::string::npos)
      << only.stderrText;
}

TEST(BenchErrorPlot, DrawsEveryScenesPointsInItsColour) {
  const std::string why = plotUnavailable();
  if (!why.empty()) GTEST_SKIP() << "plot not testable here: " << why;
#ifdef SSLPV_PLOT_BINARY
  TempDir dir;
  json rows = json::array();
  // Two scenes of five points; two Pareto points each.
  for (int s = 0; s < 2; ++s)
    for (int i = 0; i < 5; ++i)
      rows.push_back({{"scene", s ? "b/ketchup.json" : "a/marble.json"},
                      {"total_ms", 10.0 * std::pow(2.0, i) * (s + 1)},
                      {"mean_relative_error", 0.5 / (1 + i) + 0.05 * s + (i % 2) * 0.2},
                      {"pareto", i % 2 == 0 && i < 4}});
  writeText(dir / "in.json", json{{"spp", 64}, {"block", 4}, {"repeats", 3}, {"rows", rows}}.dump());
  std::vector<std::string> args;
  if (!haveDisplay()) args = {findInPath("xvfb-run")->string(), "-a", "-s", "-screen 0 1280x1024x24"};
  args.insert(args.end(), {SSLPV_PLOT_BINARY, (dir / "in.json").string(), (dir / "plot.png").string(), "--size",
                           "640x480"});
  const RunResult plot = runProgram(args);
  ASSERT_EQ(plot.exitCode, 0) << plot.stdoutText << plot.stderrText;
  const Image png = readImage(dir / "plot.png");
  ASSERT_EQ(png.width, 640);
  ASSERT_EQ(png.height, 480);
  // Background white; axes and text dark; scene 0 blue (31,119,180), scene 1 orange
  // (255,127,14) in Tableau 10. readImage returns linear values: classify by channel order.
  int dark = 0, blue = 0, orange = 0, white = 0;
  for (const glm::vec3& p : png.pixels) {
    if (p.r > 0.95f && p.g > 0.95f && p.b > 0.95f) ++white;
    else if (p.r < 0.1f && p.g < 0.1f && p.b < 0.1f) ++dark;
    else if (p.b > p.g + 0.1f && p.g > p.r) ++blue;
    else if (p.r > 0.6f && p.r > p.g + 0.3f && p.g > p.b) ++orange;
  }
  EXPECT_GT(white, 640 * 480 / 2) << "the background is white";
  EXPECT_GT(dark, 200) << "axes, ticks and labels";
  EXPECT_GT(blue, 100) << "scene a/marble's points and front";
  EXPECT_GT(orange, 100) << "scene b/ketchup's points and front";
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir.path())) left.insert(e.path().filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"in.json", "plot.png"})) << "no temporary file left";
#endif
}

TEST(BenchErrorPlot, RejectsATableWithoutRows) {
#ifndef SSLPV_PLOT_BINARY
  GTEST_SKIP() << "this build has no sslpv-plot (VTK not found at configure time)";
#else
  TempDir dir;
  writeText(dir / "in.json", R"({"spp": 1, "block": 1, "repeats": 1, "rows": []})");
  // Bad input is found before any X connection, so no display is needed.
  const RunResult plot = runProgram({SSLPV_PLOT_BINARY, (dir / "in.json").string(), (dir / "plot.png").string()});
  EXPECT_EQ(plot.exitCode, 2) << plot.stderrText;
  EXPECT_NE(plot.stderrText.find("no row"), std::string::npos) << plot.stderrText;
  EXPECT_FALSE(fs::exists(dir / "plot.png"));
#endif
}

}  // namespace
}  // namespace sslpv::test

// `sslpv view` under Xvfb: scripted input (--script), a headless run of N frames
// (--frames) and the last presented frame read back from the swapchain (--screenshot),
// compared with what `sslpv render` writes for the same camera. Skips loudly where
// xvfb-run is missing or the window cannot be presented (no GLFW, no Vulkan surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"
#include "volume/core/image_io.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;

// Small and fast on the CPU backend, the example's own camera and lights.
const std::vector<std::string> kFast = {"--size", "128x128", "--grid", "16", "--steps", "8"};

std::string xvfbSkipReason() {
  if (test::runProgram({"sh", "-c", "command -v xvfb-run"}).exitCode != 0)
    return "xvfb-run is not installed (Debian package xvfb): the viewer needs an X display";
  return {};
}

/// `sslpv view ARGS` in its own Xvfb server; `env` entries (NAME=value) go before it.
RunResult runView(const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
  std::vector<std::string> command{"env"};
  command.insert(command.end(), env.begin(), env.end());
  for (const char* part : {"xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", SSLPV_BINARY, "view"})
    command.emplace_back(part);
  command.insert(command.end(), args.begin(), args.end());
  return test::runProgram(command);
}

/// Exit 3 is the viewer's "cannot open or present a window here" (its one line says why).
#define SKIP_IF_NO_WINDOW(result)                                                                \
  if ((result).exitCode == 3) GTEST_SKIP() << "SKIPPED, the viewer cannot present here: " << (result).stderrText

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// Display values (0..255) of a PNG: what the window showed, without the sRGB round trip
/// of readImage blurring an exact comparison.
std::vector<unsigned char> pngBytes(const fs::path& file) { return toDisplayRgb8(readImage(file)); }

struct ByteDifference {
  int max = 0;
  double mean = 0.0;
};

ByteDifference difference(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b) {
  ByteDifference d;
  if (a.size() != b.size() || a.empty()) {
    d.max = 256;  // sizes differ: no agreement possible
    return d;
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const int diff = std::abs(int(a[i]) - int(b[i]));
    d.max = std::max(d.max, diff);
    sum += diff;
  }
  d.mean = sum / double(a.size());
  return d;
}

/// The example scene beside its mesh and material set in a private folder, so it can be
/// changed on disk; `edit` changes the JSON first.
fs::path copyExample(const TempDir& dir, const std::function<void(nlohmann::json&)>& edit = {}) {
  for (const char* name : {"pebble.obj", "marble_veins.vdb"})
    fs::copy_file(test::examplesDir() / name, dir / name, fs::copy_options::overwrite_existing);
  nlohmann::json scene = nlohmann::json::parse(test::readText(test::examplesDir() / "marble_pebble.json"));
  if (edit) edit(scene);
  const fs::path file = dir / "scene.json";
  test::writeText(dir / "scene.json.new", scene.dump(2));
  fs::rename(dir / "scene.json.new", file);  // the viewer polls: it must never read half a file
  return file;
}

// The viewer presents exactly the image `sslpv render` writes for the same camera: the
// frame is copied into the swapchain unchanged and read back from it. Tolerance: one
// display level (the PNG round trip), and none is needed in practice.
TEST(ViewCli, ScreenshotMatchesRenderOnTheCpuBackend) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  const RunResult viewed = runView(with({scene.string(), "--backend", "cpu", "--frames", "2", "--no-overlay",
                                         "--screenshot", (dir / "shot.png").string()},
                                        kFast));
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  EXPECT_NE(viewed.stdoutText.find("frames/s"), std::string::npos) << viewed.stdoutText;
  const RunResult rendered =
      test::runSslpv(with({"render", scene.string(), "--backend", "cpu", "-o", (dir / "ref.png").string()}, kFast));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  const ByteDifference d = difference(pngBytes(dir / "shot.png"), pngBytes(dir / "ref.png"));
  EXPECT_LE(d.max, 1) << "mean " << d.mean;
}

// The overlay draws the stage timings into the image, inside its top-left box only.
TEST(ViewCli, OverlayDrawsTimingsTopLeftOnly) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  const RunResult plain = runView(with({scene.string(), "--backend", "cpu", "--frames", "1", "--no-overlay",
                                        "--screenshot", (dir / "plain.png").string()},
                                       kFast));
  SKIP_IF_NO_WINDOW(plain);
  ASSERT_EQ(plain.exitCode, 0) << plain.stderrText;
  const RunResult shown = runView(
      with({scene.string(), "--backend", "cpu", "--frames", "1", "--screenshot", (dir / "overlay.png").string()},
           kFast));
  ASSERT_EQ(shown.exitCode, 0) << shown.stderrText;
  const std::vector<unsigned char> a = pngBytes(dir / "plain.png"), b = pngBytes(dir / "overlay.png");
  ASSERT_EQ(a.size(), b.size());
  int changedTop = 0, changedBelow = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[i]) ((i / 3) / 128 < 48 ? changedTop : changedBelow)++;  // four text lines fit in 48 rows
  EXPECT_GT(changedTop, 500) << "no text drawn";
  EXPECT_EQ(changedBelow, 0);
}

// A turntable step of 90 degrees is the render of the camera turned 90 degrees about the
// scene's up (y) axis: the example's camera at (0, 35, 85) goes to (85, 35, 0).
TEST(ViewCli, OrbitedFrameMatchesRenderOfTheTurnedCamera) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  const RunResult viewed = runView(with({scene.string(), "--backend", "cpu", "--frames", "2", "--turntable", "90",
                                         "--no-overlay", "--screenshot", (dir / "turned.png").string()},
                                        kFast));
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  const fs::path turned = copyExample(dir, [](nlohmann::json& s) { s["camera"]["position"] = {85.0, 35.0, 0.0}; });
  const RunResult rendered =
      test::runSslpv(with({"render", turned.string(), "--backend", "cpu", "-o", (dir / "ref.png").string()}, kFast));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  const RunResult still =
      test::runSslpv(with({"render", scene.string(), "--backend", "cpu", "-o", (dir / "still.png").string()}, kFast));
  ASSERT_EQ(still.exitCode, 0) << still.stderrText;
  const std::vector<unsigned char> shot = pngBytes(dir / "turned.png");
  // The turned camera's position differs from (85, 35, 0) by rounding only: a rare pixel
  // at the silhouette may flip, the image as a whole agrees.
  const ByteDifference d = difference(shot, pngBytes(dir / "ref.png"));
  EXPECT_LT(d.mean, 0.2) << "max " << d.max;
  EXPECT_GT(difference(shot, pngBytes(dir / "still.png")).mean, 5.0) << "the turn did not change the image";
}

// Dragging with the left button orbits the camera, with the right button moves the light;
// both change the image, differently.
TEST(ViewCli, ScriptedDragsOrbitTheCameraAndMoveTheLight) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  test::writeText(dir / "script.txt",
                  "# frame 1: the unchanged view, then each drag on its own frame\n"
                  "1 screenshot " + (dir / "still.png").string() + "\n"
                  "1 drag left 40 64 100 64\n"
                  "2 screenshot " + (dir / "orbited.png").string() + "\n"
                  "2 drag left 100 64 40 64\n"
                  "2 drag right 64 64 64 20\n");
  const RunResult viewed =
      runView(with({scene.string(), "--backend", "cpu", "--frames", "3", "--no-overlay", "--script",
                    (dir / "script.txt").string(), "--screenshot", (dir / "lit.png").string()},
                   kFast));
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  const std::vector<unsigned char> still = pngBytes(dir / "still.png");
  const std::vector<unsigned char> orbited = pngBytes(dir / "orbited.png");
  const std::vector<unsigned char> lit = pngBytes(dir / "lit.png");
  EXPECT_GT(difference(still, orbited).mean, 5.0) << "a left drag did not orbit the camera";
  EXPECT_GT(difference(still, lit).mean, 1.0) << "a right drag did not move the light";
  EXPECT_GT(difference(orbited, lit).mean, 1.0);
}

// An animated scene: scrubbing forward poses the deformed object at the new time, and the
// viewer shows what `sslpv render --time` draws for it (fixed steps: no warm start, so
// both start from the same light); play then moves it on by itself.
TEST(ViewCli, ScrubbedAnimationMatchesRenderAtThatTimeAndPlayMovesIt) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "bending_bar.json";
  // Four scrub steps of 0.05: t = 0.2.
  test::writeText(dir / "script.txt",
                  "1 screenshot " + (dir / "start.png").string() + "\n"
                  "1 key right\n1 key right\n1 key right\n1 key right\n"
                  "2 screenshot " + (dir / "scrubbed.png").string() + "\n"
                  "2 key space\n");
  const RunResult viewed =
      runView(with({scene.string(), "--backend", "cpu", "--frames", "12", "--no-overlay", "--script",
                    (dir / "script.txt").string(), "--screenshot", (dir / "played.png").string()},
                   kFast));
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  const RunResult rendered = test::runSslpv(with({"render", scene.string(), "--backend", "cpu", "--time", "0.2", "-o",
                                                  (dir / "ref.png").string()},
                                                 kFast));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  const std::vector<unsigned char> start = pngBytes(dir / "start.png");
  const std::vector<unsigned char> scrubbed = pngBytes(dir / "scrubbed.png");
  const ByteDifference d = difference(scrubbed, pngBytes(dir / "ref.png"));
  EXPECT_LE(d.max, 1) << "mean " << d.mean;
  EXPECT_GT(difference(start, scrubbed).mean, 1.0) << "scrubbing did not bend the bar";
  EXPECT_GT(difference(scrubbed, pngBytes(dir / "played.png")).mean, 0.1) << "play did not move the animation on";
}

/// Runs the viewer on a background thread while the test changes its files on disk.
class ViewerRun {
 public:
  explicit ViewerRun(std::vector<std::string> args)
      : thread_([this, args = std::move(args)] {
          result_ = runView(args);
          done_ = true;
        }) {}
  ~ViewerRun() {
    if (thread_.joinable()) thread_.join();
  }
  /// Waits until `file` exists (the script's marker screenshot) or the viewer exited.
  bool waitFor(const fs::path& file) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
    while (!fs::exists(file)) {
      if (done_ || std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }
  const RunResult& finish() {
    thread_.join();
    return result_;
  }

 private:
  RunResult result_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

// Saving the scene reloads it: a JSON that does not parse and a material set that does
// not load each keep the last good frame with a one-line reason; a changed material is
// then shown, as `sslpv render` draws it.
TEST(ViewCli, ReloadsChangedSceneAndKeepsLastGoodFrameOnBadOnes) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = copyExample(dir);
  auto marker = [&](int i) { return dir / ("step" + std::to_string(i) + ".png"); };
  test::writeText(dir / "script.txt", "1 screenshot " + marker(0).string() +
                                          "\n1 wait-reload-failed\n1 screenshot " + marker(1).string() +
                                          "\n1 wait-reload-failed\n1 screenshot " + marker(2).string() +
                                          "\n1 wait-reload\n");
  ViewerRun run(with({scene.string(), "--backend", "cpu", "--frames", "2", "--no-overlay", "--script",
                      (dir / "script.txt").string(), "--screenshot", (dir / "after.png").string()},
                     kFast));
  const bool started = run.waitFor(marker(0));
  if (started) {
    test::writeText(dir / "scene.json.new", "{\"units\": \"mm\", ");
    fs::rename(dir / "scene.json.new", scene);
  }
  if (started && run.waitFor(marker(1))) {
    test::writeText(dir / "broken.vdb", "not a material set");
    copyExample(dir, [](nlohmann::json& s) { s["material"]["vdb"] = "broken.vdb"; });
  }
  if (started && run.waitFor(marker(2)))
    copyExample(dir, [](nlohmann::json& s) { s["material"]["base"]["preset"] = "ketchup"; });
  const RunResult& viewed = run.finish();
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  // One warning line per bad save, naming the file at fault.
  EXPECT_NE(viewed.stderrText.find("scene.json"), std::string::npos) << viewed.stderrText;
  EXPECT_NE(viewed.stderrText.find("broken.vdb"), std::string::npos) << viewed.stderrText;
  const std::vector<unsigned char> before = pngBytes(marker(0));
  EXPECT_EQ(difference(before, pngBytes(marker(1))).max, 0) << "a scene that failed to load replaced the frame";
  EXPECT_EQ(difference(before, pngBytes(marker(2))).max, 0) << "a set that failed to load replaced the frame";

  const RunResult rendered =
      test::runSslpv(with({"render", scene.string(), "--backend", "cpu", "-o", (dir / "ref.png").string()}, kFast));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  const std::vector<unsigned char> after = pngBytes(dir / "after.png");
  EXPECT_GT(difference(before, after).mean, 5.0) << "the changed material was not shown";
  EXPECT_LE(difference(after, pngBytes(dir / "ref.png")).max, 1);
}

// The Vulkan backend's frame presents as `sslpv render --backend vulkan` writes it, with
// the validation layer silent over frames that re-shade, re-propagate and re-grid.
TEST(ViewCli, VulkanBackendMatchesRenderWithValidationSilent) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  const char* layerManifest = "/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json";
  if (!fs::exists(layerManifest))
    GTEST_SKIP() << "SKIPPED, the Vulkan validation layer is not installed (vulkan-validationlayers)";
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  const RunResult rendered =
      test::runSslpv(with({"render", scene.string(), "--backend", "vulkan", "-o", (dir / "ref.png").string()}, kFast));
  if (rendered.exitCode == 3) GTEST_SKIP() << "SKIPPED, no Vulkan backend here: " << rendered.stderrText;
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  test::writeText(dir / "script.txt", "1 screenshot " + (dir / "first.png").string() +
                                          "\n1 drag left 40 64 90 70\n2 drag right 64 64 30 64\n3 key g\n"
                                          "4 key s\n4 wheel 1\n");
  const RunResult viewed = runView(with({scene.string(), "--backend", "vulkan", "--frames", "5", "--no-overlay",
                                         "--script", (dir / "script.txt").string()},
                                        kFast),
                                   {"VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation"});
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  const std::string output = viewed.stdoutText + viewed.stderrText;
  EXPECT_EQ(output.find("Validation"), std::string::npos) << output;
  EXPECT_EQ(output.find("VUID"), std::string::npos) << output;
  EXPECT_LE(difference(pngBytes(dir / "first.png"), pngBytes(dir / "ref.png")).max, 1);
}

// A resized window rebuilds its swapchain and renders at the new size: the frame is the
// render at that size (the aspect follows), with validation silent over the rebuild.
TEST(ViewCli, ResizedWindowShowsTheRenderAtTheNewSize) {
  if (const std::string why = xvfbSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = test::examplesDir() / "marble_pebble.json";
  test::writeText(dir / "script.txt", "1 resize 96 64\n");
  std::vector<std::string> env;
  if (fs::exists("/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json"))
    env.push_back("VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation");
  const RunResult viewed = runView(with({scene.string(), "--backend", "cpu", "--frames", "2", "--no-overlay",
                                         "--script", (dir / "script.txt").string(), "--screenshot",
                                         (dir / "resized.png").string()},
                                        kFast),
                                   env);
  SKIP_IF_NO_WINDOW(viewed);
  ASSERT_EQ(viewed.exitCode, 0) << viewed.stderrText;
  const std::string output = viewed.stdoutText + viewed.stderrText;
  EXPECT_EQ(output.find("Validation"), std::string::npos) << output;
  std::vector<std::string> args = kFast;
  args[1] = "96x64";
  const RunResult rendered =
      test::runSslpv(with({"render", scene.string(), "--backend", "cpu", "-o", (dir / "ref.png").string()}, args));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.stderrText;
  const Image shot = readImage(dir / "resized.png");
  EXPECT_EQ(shot.width, 96);
  EXPECT_EQ(shot.height, 64);
  EXPECT_LE(difference(toDisplayRgb8(shot), pngBytes(dir / "ref.png")).max, 1);
}

// Bad input fails before any window opens: exit 2 and one line naming the flag or line.
TEST(ViewCli, RejectsBadFlagsAndScriptsWithOneLine) {
  TempDir dir;
  const std::string scene = (test::examplesDir() / "marble_pebble.json").string();
  test::writeText(dir / "bad.txt", "0 key g\n2 drag middle 1 2 3 4\n");
  struct Case {
    std::vector<std::string> args;
    std::string mentions;
  };
  const std::vector<Case> cases = {
      {{scene, "--backend", "metal"}, "--backend"},
      {{scene, "--size", "0x10"}, "--size"},
      {{scene, "--screenshot", (dir / "a.png").string()}, "--frames"},
      {{scene, "--frames", "1", "--screenshot", (dir / "a.exr").string()}, ".png"},
      {{scene, "--steps", "many"}, "--steps"},
      {{scene, "--script", (dir / "bad.txt").string()}, "bad.txt:2"},
      {{scene, "--script", (dir / "missing.txt").string()}, "missing.txt"},
      {{(dir / "missing.json").string()}, "missing.json"},
  };
  for (const Case& c : cases) {
    const RunResult r = test::runSslpv(with({"view"}, c.args));
    EXPECT_EQ(r.exitCode, 2) << c.mentions << ": " << r.stderrText;
    EXPECT_NE(r.stderrText.find(c.mentions), std::string::npos) << r.stderrText;
    EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
    EXPECT_FALSE(fs::exists(dir / "a.png"));
  }
}

// With no display there is no window: exit 3 and one line that says what to do instead.
TEST(ViewCli, NoDisplayIsAOneLineResourceError) {
  const RunResult r = test::runProgram({"env", "-u", "DISPLAY", "-u", "WAYLAND_DISPLAY", SSLPV_BINARY, "view",
                                        (test::examplesDir() / "marble_pebble.json").string(), "--frames", "1"});
  EXPECT_EQ(r.exitCode, 3) << r.stderrText;
  EXPECT_NE(r.stderrText.find("sslpv render"), std::string::npos) << r.stderrText;
  EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
}

}  // namespace
}  // namespace sslpv

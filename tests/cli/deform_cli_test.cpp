// `sslpv render --time / --frames` and `sslpv reference --time` on a deforming scene, run
// as a user runs them: the sequence's files, its progress lines, and clean errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_rejects.h"
#include "test_support.h"
#include "volume/core/image_io.h"

namespace sslpv::test {
namespace {

using nlohmann::json;

/// The small scene as a bar that bends a quarter turn over t in [0, 1].
json bendingScene() {
  json scene = smallScene();
  scene["mesh"] = json::parse(R"({"primitive": "box", "min": [-10, -2, -2], "max": [10, 2, 2], "segments": [20, 2, 2]})");
  scene["deformers"] = json::parse(R"([{"type": "bend", "axis": "x", "toward": "y", "center": [-10, 0, 0],
      "length": 20, "angle": [{"t": 0, "value": 0}, {"t": 1, "value": 90}]}])");
  return scene;
}

class DeformCli : public CliRejects {};

TEST_F(DeformCli, FramesWriteOneDistinctFilePerFrameWithAProgressLineEach) {
  writeScene(bendingScene());
  const std::string pattern = (dir_ / "bar_%04d.png").string();
  // Frames 0, 12 and 24 at 24 per unit: t = 0, 0.5 and 1.
  const RunResult r = run({"render", scenePath().string(), "--frames", "0:24:12", "-o", pattern, "--backend", "cpu"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  std::vector<Image> images;
  for (const char* name : {"bar_0000.png", "bar_0012.png", "bar_0024.png"}) {
    ASSERT_TRUE(std::filesystem::exists(dir_ / name)) << name;
    images.push_back(readImage(dir_ / name));
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bar_0001.png"));
  EXPECT_NE(images[0].pixels, images[1].pixels);
  EXPECT_NE(images[1].pixels, images[2].pixels);
  EXPECT_NE(images[0].pixels, images[2].pixels);
  // stderr is a pipe here: plain lines, no carriage return.
  EXPECT_EQ(r.stderrText.find('\r'), std::string::npos);
  EXPECT_NE(r.stderrText.find("render: frame 1/3 (t = 0)"), std::string::npos) << r.stderrText;
  EXPECT_NE(r.stderrText.find("render: frame 3/3 (t = 1)"), std::string::npos) << r.stderrText;
}

TEST_F(DeformCli, VulkanFramesToo) {
  writeScene(bendingScene());
  const RunResult r =
      run({"render", scenePath().string(), "--frames", "0:24:24", "-o", (dir_ / "v%d.png").string(), "--backend",
           "vulkan"});
  if (r.exitCode == 3) GTEST_SKIP() << "SKIPPED, no Vulkan backend here: " << r.stderrText;
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_NE(readImage(dir_ / "v0.png").pixels, readImage(dir_ / "v24.png").pixels);
}

TEST_F(DeformCli, TimeRendersThePoseOfThatFrame) {
  writeScene(bendingScene());
  const auto frame = dir_ / "t.png";
  ASSERT_EQ(run({"render", scenePath().string(), "--time", "0.5", "-o", frame.string(), "--backend", "cpu"}).exitCode,
            0);
  ASSERT_EQ(run({"render", scenePath().string(), "--frames", "12:12", "-o", (dir_ / "f%d.png").string(), "--backend",
                 "cpu"})
                .exitCode,
            0);
  EXPECT_EQ(readImage(frame).pixels, readImage(dir_ / "f12.png").pixels);
}

TEST_F(DeformCli, ReferenceTracesTheDeformedFrame) {
  writeScene(bendingScene());
  const auto straight = dir_ / "ref0.exr", bent = dir_ / "ref1.exr";
  for (const auto& [time, file] : {std::pair{"0", straight}, std::pair{"1", bent}}) {
    const RunResult r = run({"reference", scenePath().string(), "--time", time, "--spp", "1", "-o", file.string()});
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  }
  EXPECT_NE(readImage(straight).pixels, readImage(bent).pixels);
}

TEST_F(DeformCli, BadFrameRangesAreOneLineInputErrors) {
  writeScene(bendingScene());
  const std::string pattern = (dir_ / "o_%04d.png").string();
  for (const char* range : {"5:2", "a:b", "1", "0:3:0", "0:1:2:3", "-1:3"}) {
    SCOPED_TRACE(range);
    expectRejected(run({"render", scenePath().string(), "--frames", range, "-o", pattern}), {"--frames"});
  }
}

TEST_F(DeformCli, BadPatternsAreOneLineInputErrors) {
  writeScene(bendingScene());
  for (const char* name : {"plain.png", "two_%d_%d.png", "bad_%s.png", "pct_%5d.png"}) {
    SCOPED_TRACE(name);
    expectRejected(run({"render", scenePath().string(), "--frames", "0:2", "-o", (dir_ / name).string()}), {"-o"});
  }
  expectRejected(render({"--time", "1", "--frames", "0:1"}), {"--time", "--frames"});
  expectRejected(render({"--time", "1e9"}), {"--time"});
}

TEST_F(DeformCli, AFoldingFrameIsRejectedBeforeAnyFrameIsWritten) {
  json scene = bendingScene();
  scene["deformers"][0]["angle"][1]["value"] = 400;  // past half a turn by t = 0.5
  writeScene(scene);
  expectRejected(run({"render", scenePath().string(), "--frames", "0:24:6", "-o", (dir_ / "o_%02d.png").string()}),
                 {"scene.json", "deformers[0]", "t = 0.5"});
}

TEST_F(DeformCli, DeformerKeyErrorsNameThePath) {
  json scene = bendingScene();
  scene["deformers"][0]["angle"][1]["t"] = "late";
  writeScene(scene);
  expectRejected(render(), {"scene.json", "deformers[0].angle[1].t"});
}

}  // namespace
}  // namespace sslpv::test

// `sslpv render --time` on a skinned glTF scene (mesh.animation), run as a user runs it:
// the pose changes the image, a sequence renders, and a bad clip is a one-line error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_rejects.h"
#include "skinned_rig.h"
#include "test_support.h"
#include "volume/core/image_io.h"

namespace sslpv::test {
namespace {

using nlohmann::json;

class SkinCli : public CliRejects {
 protected:
  /// The bar rig beside the scene, the scene playing `animation`.
  void writeSkinnedScene(const json& animation) {
    writeText(dir_ / "bar.gltf", writeGltf(bendingBarRig()));
    json scene = json::parse(skinnedBarScene("bar.gltf", ""));
    scene["mesh"]["animation"] = animation;
    writeScene(scene);
  }
};

TEST_F(SkinCli, TimePosesTheClip) {
  writeSkinnedScene("Bend");
  const auto straight = dir_ / "t0.png", bent = dir_ / "t1.png", again = dir_ / "f24.png";
  for (const auto& [time, file] : {std::pair{"0", straight}, std::pair{"1", bent}}) {
    const RunResult r = run({"render", scenePath().string(), "--time", time, "-o", file.string(), "--backend", "cpu"});
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_EQ(r.stderrText.find("every time renders the same image"), std::string::npos) << r.stderrText;
  }
  EXPECT_NE(readImage(straight).pixels, readImage(bent).pixels);
  // Frame 24 at 24 fps is t = 1 s: a sequence's frame is the --time render.
  const RunResult r = run({"render", scenePath().string(), "--frames", "0:24:24", "-o",
                           (dir_ / "f%d.png").string(), "--backend", "cpu"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_EQ(readImage(bent).pixels, readImage(again).pixels);
}

TEST_F(SkinCli, VulkanPosesTheClipToo) {
  writeSkinnedScene(1);
  const auto bent = dir_ / "v1.png", straight = dir_ / "v0.png";
  const RunResult r = run({"render", scenePath().string(), "--time", "1", "-o", bent.string(), "--backend", "vulkan"});
  if (r.exitCode == 3) GTEST_SKIP() << "SKIPPED, no Vulkan backend here: " << r.stderrText;
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_EQ(run({"render", scenePath().string(), "--time", "0", "-o", straight.string(), "--backend", "vulkan"}).exitCode,
            0);
  EXPECT_NE(readImage(straight).pixels, readImage(bent).pixels);
}

TEST_F(SkinCli, AnUnknownClipIsAOneLineErrorListingTheClips) {
  writeSkinnedScene("Wave");
  expectRejected(render({"--backend", "cpu"}), {"scene.json", "mesh.animation", "bar.gltf", "'Wave' not found",
                                                "Idle, Bend"});
}

TEST_F(SkinCli, AClipOnAMeshWithoutSkinIsAOneLineError) {
  GltfRig plain = bendingBarRig();
  plain.vertexJoints.clear();
  plain.vertexWeights.clear();
  writeText(dir_ / "bar.gltf", writeGltf(plain));
  json scene = json::parse(skinnedBarScene("bar.gltf", "\"Bend\""));
  writeScene(scene);
  expectRejected(render({"--backend", "cpu"}), {"scene.json", "mesh.animation", "bar.gltf", "no skin"});
}

TEST_F(SkinCli, AClipWithDeformersIsRejected) {
  writeSkinnedScene("Bend");
  json scene = json::parse(readText(scenePath()));
  scene["deformers"] = json::parse(R"([{"type": "twist", "angle": 10}])");
  writeScene(scene);
  expectRejected(render(), {"scene.json", "deformers", "mesh.animation"});
}

}  // namespace
}  // namespace sslpv::test

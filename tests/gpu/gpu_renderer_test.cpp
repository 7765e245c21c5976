// The command line's behaviour without a usable Vulkan device. (The Vulkan renderer's
// frame cache is tests/lpv/frame_cache_test.cpp, run on both backends.)
#include <gtest/gtest.h>

#include <cstdlib>

#include "test_support.h"

namespace {
using namespace sslpv;

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

// The Vulkan device and resources: creation under validation, device selection by name,
// error messages, and RAII ownership (leaks would show up as validation messages).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "gpu/vk/compute.h"
#include "gpu/vk/resources.h"
#include "gpu/vk/vk_check.h"
#include "gpu_test_fixture.h"

namespace {
using namespace sslpv;
using sslpv::test::GpuTest;

/// Sets an environment variable for one scope and restores the previous value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, hadOld_ = true;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (hadOld_)
      setenv(name_, old_.c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool hadOld_ = false;
};

TEST(VkCheck, FailureMessageNamesCallResultAndPlace) {
  try {
    gpu::throwOnFailure(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkCreateBuffer(...)", "/src/sslpv/gpu/buffer.cpp", 42);
    FAIL() << "no exception";
  } catch (const GpuError& e) {
    EXPECT_STREQ(e.what(), "vkCreateBuffer(...) failed: VK_ERROR_OUT_OF_DEVICE_MEMORY at gpu/buffer.cpp:42");
  }
  EXPECT_NO_THROW(gpu::throwOnFailure(VK_SUCCESS, "vkFoo()", __FILE__, __LINE__));
  EXPECT_EQ(gpu::resultName(VkResult(-12345)), "VkResult(-12345)");
}

TEST(VkCheck, MacroReportsTheExpression) {
  const auto failingCall = [] { return VK_ERROR_DEVICE_LOST; };
  try {
    SSLPV_VK_CHECK(failingCall());
    FAIL() << "no exception";
  } catch (const GpuError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("failingCall() failed: VK_ERROR_DEVICE_LOST at "), std::string::npos) << message;
    EXPECT_NE(message.find("gpu_device_test.cpp:"), std::string::npos) << message;
  }
}

TEST_F(GpuTest, DeviceIsCreatedWithValidationAndAComputeQueue) {
  EXPECT_TRUE(device().validationEnabled());
  EXPECT_FALSE(device().name().empty());
  EXPECT_GE(device().properties().apiVersion, std::uint32_t(VK_API_VERSION_1_2));
  EXPECT_NE(device().queue(), VkQueue(VK_NULL_HANDLE));
  std::cout << "Vulkan device: " << device().name() << " (unified memory: " << device().unifiedMemory() << ")\n";
}

TEST_F(GpuTest, UnknownDeviceNameIsAClearGpuError) {
  ScopedEnv env("SSLPV_VULKAN_DEVICE", "no-such-gpu-42");
  try {
    gpu::VulkanDevice other;
    FAIL() << "a device named no-such-gpu-42 was accepted: " << other.name();
  } catch (const NoVulkanDeviceError& e) {
    FAIL() << "must not look like a machine without Vulkan: " << e.what();
  } catch (const GpuError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("SSLPV_VULKAN_DEVICE=\"no-such-gpu-42\" matches no Vulkan device"), std::string::npos)
        << message;
    // The message lists what is there, so the user can pick one.
    EXPECT_NE(message.find(device().name()), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
  }
}

TEST_F(GpuTest, DeviceNameSubstringSelectsThatDevice) {
  // Any case-insensitive substring works; take the middle of the real name, upper-cased.
  std::string name = device().name();
  std::string part = name.substr(name.size() / 4, std::max<std::size_t>(1, name.size() / 2));
  for (char& c : part) c = char(std::toupper(static_cast<unsigned char>(c)));
  ScopedEnv env("SSLPV_VULKAN_DEVICE", part.c_str());
  gpu::VulkanDevice chosen;
  EXPECT_EQ(chosen.name(), name);
  gpu::DeviceOptions explicitName;
  explicitName.deviceName = "definitely-not-a-device";
  EXPECT_THROW(gpu::VulkanDevice{explicitName}, GpuError) << "an explicit name overrides the environment";
}

TEST_F(GpuTest, BuffersAreMovableOwnersAndMappedWhereDeviceMemoryIsTheHosts) {
  gpu::Buffer host(device(), 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUse::Host);
  ASSERT_NE(host.mapped(), nullptr) << "host buffers are always mapped";
  std::memset(host.mapped(), 0x5a, 256);
  gpu::Buffer moved = std::move(host);
  EXPECT_EQ(host.handle(), VkBuffer(VK_NULL_HANDLE));
  EXPECT_EQ(host.mapped(), nullptr);
  EXPECT_EQ(moved.mappedAs<unsigned char>()[255], 0x5a);
  gpu::Buffer onDevice(device(), 1024, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUse::Device);
  EXPECT_EQ(onDevice.mapped() != nullptr, device().unifiedMemory());
  moved = std::move(onDevice);  // releases the first buffer; validation reports a leak otherwise
  EXPECT_EQ(moved.size(), 1024u);
}

TEST_F(GpuTest, TimestampsAdvanceAcrossASubmission) {
  if (device().timestampValidBits() == 0) GTEST_SKIP() << "SKIPPED, the queue has no timestamps";
  gpu::CommandContext commands(device());
  gpu::TimestampQueries timestamps(device(), 2);
  gpu::Buffer buffer(device(), 1 << 20, VK_BUFFER_USAGE_TRANSFER_DST_BIT, gpu::MemoryUse::Device);
  VkCommandBuffer cmd = commands.begin();
  timestamps.reset(cmd);
  timestamps.write(cmd, 0);
  vkCmdFillBuffer(cmd, buffer.handle(), 0, VK_WHOLE_SIZE, 0);
  timestamps.write(cmd, 1);
  commands.submitAndWait();
  const std::vector<double> ms = timestamps.readMilliseconds(2);
  EXPECT_EQ(ms[0], 0.0);
  EXPECT_GE(ms[1], 0.0);
  EXPECT_LT(ms[1], 10000.0);
}

}  // namespace

#pragma once
// Fixture for every GPU test: a Vulkan device with validation on, skipped loudly only
// when the machine has no Vulkan device, and a check at TearDown (after the device and
// everything on it are destroyed, so leaks count too) that validation reported nothing.
#include <gtest/gtest.h>

#include <memory>

#include "gpu/vk/device.h"

namespace sslpv::test {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      gpu::DeviceOptions options;
      options.validation = true;
      device_ = std::make_unique<gpu::VulkanDevice>(options);
    } catch (const NoVulkanDeviceError& e) {
      GTEST_SKIP() << "SKIPPED, no Vulkan device on this machine: " << e.what();
    }
    log_ = device_->validationLog();
  }

  void TearDown() override {
    device_.reset();
    if (log_) {
      EXPECT_EQ(log_->count(), 0u) << "validation messages:\n" << log_->text();
    }
  }

  gpu::VulkanDevice& device() { return *device_; }

 private:
  std::unique_ptr<gpu::VulkanDevice> device_;
  std::shared_ptr<const gpu::ValidationLog> log_;
};

}  // namespace sslpv::test

#pragma once
// Fixture for every GPU test: a Vulkan device with validation on, skipped loudly only
// when the machine has no Vulkan device, and a check at TearDown that validation
// reported nothing. ValidatedDevice serves fixtures of their own (parameterised suites).
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "gpu/vk/device.h"

namespace sslpv::test {

/// A Vulkan device with validation on, and the check at the end that validation
/// reported nothing (after the device and everything on it are destroyed, so leaks count
/// too). Fixtures call GTEST_SKIP with skipReason() when open() fails.
class ValidatedDevice {
 public:
  bool open() {
    try {
      gpu::DeviceOptions options;
      options.validation = true;
      device_ = std::make_unique<gpu::VulkanDevice>(options);
    } catch (const NoVulkanDeviceError& e) {
      skipReason_ = std::string("SKIPPED, no Vulkan device on this machine: ") + e.what();
      return false;
    }
    log_ = device_->validationLog();
    return true;
  }
  const std::string& skipReason() const { return skipReason_; }
  gpu::VulkanDevice& device() { return *device_; }

  void closeAndCheck() {
    device_.reset();
    if (log_) {
      EXPECT_EQ(log_->count(), 0u) << "validation messages:\n" << log_->text();
    }
  }

 private:
  std::unique_ptr<gpu::VulkanDevice> device_;
  std::shared_ptr<const gpu::ValidationLog> log_;
  std::string skipReason_;
};

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!device_.open()) GTEST_SKIP() << device_.skipReason();
  }
  void TearDown() override { device_.closeAndCheck(); }
  gpu::VulkanDevice& device() { return device_.device(); }

 private:
  ValidatedDevice device_;
};

}  // namespace sslpv::test

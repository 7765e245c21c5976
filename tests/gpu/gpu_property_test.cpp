// Property (c) of the property tests (property_test.cpp): on seeded random valid scenes
// (tests/support/random_scenes.h: both schemes, fixed and auto steps, heterogeneous material sets,
// every light kind) the Vulkan backend shows what the CPU backend computes, within the
// tolerances of gpu_agreement_test.cpp. Skips loudly without a Vulkan device (GpuTest).
#include <gtest/gtest.h>

#include "gpu_agreement_check.h"
#include "gpu_test_fixture.h"
#include "random_scenes.h"

namespace sslpv::test {
namespace {

class GpuProperty : public GpuTest {};

TEST_F(GpuProperty, CpuAndVulkanAgreeOnRandomScenes) {
  constexpr int kScenes = 24;
  for (int k = 0; k < kScenes; ++k) {
    const std::uint64_t seed = 9000 + std::uint64_t(k);
    const RandomScene r = randomScene(seed, 64);
    SCOPED_TRACE("seed " + std::to_string(seed) + " (randomScene(" + std::to_string(seed) + ", 64))" +
                 (r.set ? " with a material set" : "") + ": " + r.json);
    expectGpuAgreement(r.scene, device(), r.set);
    if (HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace sslpv::test

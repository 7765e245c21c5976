// The records shared by C++ and GLSL (device_shared/lpv_shared.h) have the same layout on both
// sides: C++ fills each field with a distinct value, shaders/layout_probe.comp reads every
// field by name (as GLSL lays it out) and copies it out in declaration order; each value
// must come back at the position of its field.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu_test_fixture.h"
#include "device_shared/lpv_shared.h"
#include "shaders/spirv_library.h"

namespace {
using namespace sslpv;
using sslpv::test::GpuTest;

std::uint32_t bitsOf(int v) { return std::uint32_t(v); }
std::uint32_t bitsOf(std::uint32_t v) { return v; }
std::uint32_t bitsOf(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

/// Distinct, recognizable values per field: 1000 + i as int, or 0.5 + i as float.
template <typename T>
T distinct(int i) {
  return T(std::is_floating_point_v<T> ? 0.5 + i : 1000 + i);
}

TEST_F(GpuTest, SharedRecordsHaveTheSameLayoutInCppAndGlsl) {
  using gpu::LpvControl;
  using gpu::LpvStepPush;
  LpvStepPush push{};
  LpvControl control{};
  std::vector<std::uint32_t> expected;
  std::vector<std::string> names;
  int i = 0;
#define SSLPV_FILL_PUSH(type, name)      \
  push.name = distinct<type>(i++);       \
  expected.push_back(bitsOf(push.name)); \
  names.push_back("LpvStepPush::" #name);
  SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_FILL_PUSH)
#define SSLPV_FILL_CONTROL(type, name)      \
  control.name = distinct<type>(i++);       \
  expected.push_back(bitsOf(control.name)); \
  names.push_back("LpvControl::" #name);
  SSLPV_LPV_CONTROL_FIELDS(SSLPV_FILL_CONTROL)
#undef SSLPV_FILL_PUSH
#undef SSLPV_FILL_CONTROL

  gpu::VulkanDevice& dev = device();
  gpu::DescriptorSetLayout layout = gpu::makeStorageBufferSetLayout(dev, 2);
  // The push range is exactly sizeof the C++ struct: a GLSL block larger than that would
  // be a validation error, which the fixture catches.
  gpu::ComputePipeline probe(dev, spirv::layout_probe_comp(), layout.get(), sizeof(LpvStepPush));
  gpu::Buffer input(dev, sizeof(LpvControl), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, gpu::MemoryUse::Host);
  gpu::Buffer output(dev, expected.size() * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                     gpu::MemoryUse::Host);
  std::memcpy(input.mapped(), &control, sizeof control);
  std::memset(output.mapped(), 0xff, output.size());
  gpu::StorageBufferSets sets(dev, layout.get(), 2, 1);
  sets.write(0, 0, input);
  sets.write(0, 1, output);

  gpu::CommandContext commands(dev);
  VkCommandBuffer cmd = commands.begin();
  probe.bind(cmd, sets.set(0), &push, sizeof push);
  vkCmdDispatch(cmd, 1, 1, 1);
  gpu::toHostBarrier(cmd);
  commands.submitAndWait();

  const std::uint32_t* fields = output.mappedAs<const std::uint32_t>();
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_EQ(fields[k], expected[k]) << names[k] << " is not where C++ put it";
}

}  // namespace

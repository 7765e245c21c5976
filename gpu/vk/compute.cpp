#include "gpu/vk/compute.h"

namespace sslpv::gpu {

DescriptorSetLayout makeStorageBufferSetLayout(const VulkanDevice& device, std::uint32_t bindingCount,
                                               VkShaderStageFlags stages) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
  for (std::uint32_t i = 0; i < bindingCount; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = stages;
  }
  VkDescriptorSetLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  info.bindingCount = bindingCount;
  info.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateDescriptorSetLayout(device.handle(), &info, nullptr, &layout));
  return DescriptorSetLayout(device.handle(), layout);
}

ComputePipeline::ComputePipeline(const VulkanDevice& device, const spirv::SpirvCode& code,
                                 VkDescriptorSetLayout setLayout, std::uint32_t pushConstantBytes,
                                 const std::vector<std::uint32_t>& specialization) {
  const VkDevice vk = device.handle();
  VkShaderModuleCreateInfo moduleInfo{};
  moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  moduleInfo.codeSize = code.byteSize();
  moduleInfo.pCode = code.words;
  VkShaderModule module = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateShaderModule(vk, &moduleInfo, nullptr, &module));
  module_ = ShaderModule(vk, module);

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
  VkPipelineLayoutCreateInfo layoutInfo{};
  layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout;
  layoutInfo.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreatePipelineLayout(vk, &layoutInfo, nullptr, &layout));
  layout_ = PipelineLayout(vk, layout);

  std::vector<VkSpecializationMapEntry> entries(specialization.size());
  for (std::uint32_t i = 0; i < entries.size(); ++i)
    entries[i] = VkSpecializationMapEntry{i, std::uint32_t(i * sizeof(std::uint32_t)), sizeof(std::uint32_t)};
  VkSpecializationInfo specializationInfo{};
  specializationInfo.mapEntryCount = std::uint32_t(entries.size());
  specializationInfo.pMapEntries = entries.data();
  specializationInfo.dataSize = specialization.size() * sizeof(std::uint32_t);
  specializationInfo.pData = specialization.data();

  VkComputePipelineCreateInfo info{};

  info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = specialization.empty() ? nullptr : &specializationInfo;
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateComputePipelines(vk, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  pipeline_ = Pipeline(vk, pipeline);
}

void ComputePipeline::bind(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, std::uint32_t pushBytes) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.get());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_.get(), 0, 1, &set, 0, nullptr);
  if (pushBytes > 0) vkCmdPushConstants(cmd, layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
}

StorageBufferSets::StorageBufferSets(const VulkanDevice& device, VkDescriptorSetLayout layout,
                                     std::uint32_t bindingCount, std::uint32_t setCount)
    : device_(device.handle()) {
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindingCount * setCount};
  VkDescriptorPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  poolInfo.maxSets = setCount;
  poolInfo.poolSizeCount = 1;
  poolInfo.pPoolSizes = &size;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateDescriptorPool(device_, &poolInfo, nullptr, &pool));
  pool_ = DescriptorPool(device_, pool);

  const std::vector<VkDescriptorSetLayout> layouts(setCount, layout);
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = setCount;
  allocate.pSetLayouts = layouts.data();
  sets_.resize(setCount);
  SSLPV_VK_CHECK(vkAllocateDescriptorSets(device_, &allocate, sets_.data()));
}

void StorageBufferSets::write(std::size_t index, std::uint32_t binding, const Buffer& buffer) const {
  VkDescriptorBufferInfo bufferInfo{buffer.handle(), 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet write{};
  write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  write.dstSet = sets_.at(index);
  write.dstBinding = binding;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &bufferInfo;
  vkUpdateDescriptorSets(device_, 1, &write, 0, nullptr);
}

CommandContext::CommandContext(const VulkanDevice& device) : device_(&device) {
  const VkDevice vk = device.handle();
  VkCommandPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = device.queueFamily();
  VkCommandPool pool = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateCommandPool(vk, &poolInfo, nullptr, &pool));
  pool_ = CommandPool(vk, pool);

  VkCommandBufferAllocateInfo allocate{};

  allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  allocate.commandPool = pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  SSLPV_VK_CHECK(vkAllocateCommandBuffers(vk, &allocate, &cmd_));

  VkFenceCreateInfo fenceInfo{};

  fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkFence fence = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateFence(vk, &fenceInfo, nullptr, &fence));
  fence_ = Fence(vk, fence);
}

VkCommandBuffer CommandContext::begin() {
  SSLPV_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo info{};
  info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  SSLPV_VK_CHECK(vkBeginCommandBuffer(cmd_, &info));
  return cmd_;
}

void CommandContext::submitAndWait() {
  SSLPV_VK_CHECK(vkEndCommandBuffer(cmd_));
  VkFence fence = fence_.get();
  SSLPV_VK_CHECK(vkResetFences(device_->handle(), 1, &fence));
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  device_->submit(submit, fence);
  SSLPV_VK_CHECK(vkWaitForFences(device_->handle(), 1, &fence, VK_TRUE, UINT64_MAX));
}

namespace {
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}
}  // namespace

void computeToComputeBarrier(VkCommandBuffer cmd) {
  memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void deviceWritesBarrier(VkCommandBuffer cmd) {
  constexpr VkPipelineStageFlags stages = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  memoryBarrier(cmd, stages, VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, stages,
                VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
                    VK_ACCESS_SHADER_WRITE_BIT);
}

void toHostBarrier(VkCommandBuffer cmd) {
  memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
}

TimestampQueries::TimestampQueries(const VulkanDevice& device, std::uint32_t capacity)
    : device_(device.handle()), capacity_(capacity), periodNs_(device.timestampPeriodNs()) {
  const std::uint32_t bits = device.timestampValidBits();
  if (bits == 0) return;
  validMask_ = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
  VkQueryPoolCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = capacity;
  VkQueryPool pool = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateQueryPool(device_, &info, nullptr, &pool));
  pool_ = QueryPool(device_, pool);
}

void TimestampQueries::reset(VkCommandBuffer cmd) {
  if (pool_) vkCmdResetQueryPool(cmd, pool_.get(), 0, capacity_);
}

void TimestampQueries::write(VkCommandBuffer cmd, std::uint32_t index) {
  if (pool_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), index);
}

std::vector<double> TimestampQueries::readMilliseconds(std::uint32_t count) const {
  std::vector<double> ms(count, 0.0);
  if (!pool_ || count == 0) return ms;
  std::vector<std::uint64_t> ticks(count);
  SSLPV_VK_CHECK(vkGetQueryPoolResults(device_, pool_.get(), 0, count, count * sizeof(std::uint64_t), ticks.data(),
                                       sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  for (std::uint32_t i = 0; i < count; ++i) ms[i] = double((ticks[i] - ticks[0]) & validMask_) * periodNs_ * 1e-6;
  return ms;
}

}  // namespace sslpv::gpu

#include "gpu/passes/gpu_propagation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <string>

#include "gpu/passes/propagation_items.h"
#include "volume/core/error.h"
#include "volume/lpv/sh.h"

namespace sslpv::gpu {
namespace {

// Bindings of shaders/lpv_step_common.glsl and lpv_reduce.comp.
constexpr std::uint32_t kBindings = 12;
constexpr bool kTexelBinding[kBindings] = {true, false, false, true, true, false, false, false, false, true, false, true};
constexpr VkDeviceSize kVec4 = 4 * sizeof(float);
constexpr VkDeviceSize kFieldVec4PerCell = 3;   // one vec4 of (c0, c1x, c1y, c1z) per channel
constexpr VkDeviceSize kFactorVec4PerCell = SSLPV_FACTOR_VEC4_PER_CELL;
constexpr VkDeviceSize kEnergyRowBytes = SSLPV_ENERGY_FLOATS * sizeof(float);
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
constexpr VkBufferUsageFlags kField = kStorage | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
void requireFrame(const ShGrid& grid, const GridFrame& frame, const char* what) {
  if (grid.frame.dims != frame.dims)
    throw GpuError(std::string("GpuPropagator: ") + what + " grid is not on the propagator's frame");
  for (const std::vector<float>& plane : grid.planes)
    if (plane.size() != frame.cellCount())
      throw GpuError(std::string("GpuPropagator: ") + what + " grid planes do not match its frame");
}

/// The kernel keeps a tile's x neighbours in one subgroup: it needs shuffles and sums in
/// compute shaders, and subgroups of at least a tile's width.
void requireSubgroups(const VulkanDevice& device) {
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  VkPhysicalDeviceProperties2 properties{};
  properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  properties.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(device.physicalDevice(), &properties);
  constexpr VkSubgroupFeatureFlags needed = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT |
                                            VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT |
                                            VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
  if (subgroup.subgroupSize < SSLPV_TILE_X || !(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
      (subgroup.supportedOperations & needed) != needed)
    throw GpuError("GPU propagation needs compute subgroups of at least " + std::to_string(SSLPV_TILE_X) +
                   " lanes with shuffle and arithmetic operations; " + device.name() + " has " +
                   std::to_string(subgroup.subgroupSize) + " lanes");
}

DescriptorSetLayout makeSetLayout(const VulkanDevice& device) {
  VkDescriptorSetLayoutBinding bindings[kBindings]{};
  for (std::uint32_t i = 0; i < kBindings; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType =
        kTexelBinding[i] ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  info.bindingCount = kBindings;
  info.pBindings = bindings;
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateDescriptorSetLayout(device.handle(), &info, nullptr, &layout));
  return DescriptorSetLayout(device.handle(), layout);
}

VkBufferView makeTexelView(const VulkanDevice& device, const Buffer& buffer) {
  VkBufferViewCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
  info.buffer = buffer.handle();
  info.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  info.range = VK_WHOLE_SIZE;
  VkBufferView view = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateBufferView(device.handle(), &info, nullptr, &view));
  return view;
}

/// Makes compute writes visible to every later read (shading, copies, the host).
void toLaterReadsBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0,
                       nullptr);
}

}  // namespace

GpuPropagator::GpuPropagator(const VulkanDevice& device, const GridFrame& frame, const StepFactors& factors,
                             const GpuPropagatorOptions& options)
    : device_(device), frame_(frame), options_(options), commands_(device) {
  const VkPhysicalDeviceLimits& limits = device.properties().limits;
  const bool factorsFit = factors.active.size() == frame.cellCount() &&
                          factors.rowActive.size() == std::size_t(frame.dims.y) * frame.dims.z;
  if (options_.tileRows <= 0)  // factors that do not fit are rejected by setFactors() below
    options_.tileRows = factorsFit ? chooseTileRows(frame, factors) : kWideTileRows;
  if (options_.tileRows > 32 || options_.stepsPerSubmission < 1 || options_.zChunk < 0)
    throw GpuError("GpuPropagatorOptions: tileRows must be 1..32, stepsPerSubmission >= 1, zChunk >= 0");

  // The private grids are padded to whole tiles; they are at least as large as the shared ones.
  tilesX_ = (std::max(frame.dims.x, 1) + SSLPV_TILE_X - 1) / SSLPV_TILE_X;
  tilesY_ = (std::max(frame.dims.y, 1) + options_.tileRows - 1) / options_.tileRows;
  const std::size_t tiledCells = std::size_t(tilesX_) * SSLPV_TILE_X * tilesY_ * options_.tileRows * std::max(frame.dims.z, 1);
  const VkDeviceSize fieldBytes = std::max<std::size_t>(frame.cellCount(), 1) * kFieldVec4PerCell * kVec4;
  const VkDeviceSize tiledBytes = tiledCells * kFieldVec4PerCell * kVec4;
  // The factor grid has the most texels per cell (it is read only through its texel view).
  const VkDeviceSize texelsPerCell = std::max(kFieldVec4PerCell, kFactorVec4PerCell);
  if (tiledBytes > limits.maxStorageBufferRange || tiledCells * texelsPerCell > limits.maxTexelBufferElements)
    throw ResourceError("LPV grid " + std::to_string(frame.dims.x) + "x" + std::to_string(frame.dims.y) + "x" +
                        std::to_string(frame.dims.z) + " needs " + std::to_string(tiledBytes >> 20) +
                        " MiB per light field, more than the Vulkan device's storage-buffer range of " +
                        std::to_string(limits.maxStorageBufferRange >> 20) + " MiB");
  requireSubgroups(device);

  setLayout_ = makeSetLayout(device);
  const auto rows = std::uint32_t(options_.tileRows);
  for (std::uint32_t variant = 0; variant < 2; ++variant) {
    propagatePipelines_[variant] =
        ComputePipeline(device, spirv::lpv_propagate_comp(), setLayout_.get(), sizeof(LpvStepPush), {rows, variant});
    finishPipelines_[variant] =
        ComputePipeline(device, spirv::lpv_accumulate_comp(), setLayout_.get(), sizeof(LpvStepPush), {rows, variant});
  }
  reducePipeline_ = ComputePipeline(device, spirv::lpv_reduce_comp(), setLayout_.get(), sizeof(LpvStepPush));
  importPipeline_ = ComputePipeline(device, spirv::lpv_import_comp(), setLayout_.get(), sizeof(LpvStepPush), {rows});

  linearSource_ = Buffer(device, fieldBytes, kField, MemoryUse::Device);
  linearAccumulated_ = Buffer(device, fieldBytes, kField, MemoryUse::Device);
  for (Buffer& field : tiled_) field = Buffer(device, tiledBytes, kField, MemoryUse::Device);
  tiledAccumulated_ = Buffer(device, tiledBytes, kField, MemoryUse::Device);
  factors_ = Buffer(device, tiledCells * kFactorVec4PerCell * kVec4, kField, MemoryUse::Device);
  control_ = Buffer(device, sizeof(LpvControl), kStorage, MemoryUse::Host);
  stepTotals_ = Buffer(device, VkDeviceSize(options_.stepsPerSubmission) * kEnergyRowBytes, kStorage, MemoryUse::Host);
  staging_ = options_.forceStaging || !tiled_[0].mapped() || !linearSource_.mapped() || !factors_.mapped();
  if (staging_) stagingBuffer_ = Buffer(device, std::max(tiledBytes, factors_.size()), kStorage, MemoryUse::Host);
  for (int k = 0; k < 2; ++k) tiledViews_[k] = BufferView(device.handle(), makeTexelView(device, tiled_[k]));
  tiledAccumulatedView_ = BufferView(device.handle(), makeTexelView(device, tiledAccumulated_));
  factorsView_ = BufferView(device.handle(), makeTexelView(device, factors_));
  linearSourceView_ = BufferView(device.handle(), makeTexelView(device, linearSource_));

  const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 2 * 5},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * 7}};
  VkDescriptorPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  poolInfo.maxSets = 2;
  poolInfo.poolSizeCount = 2;
  poolInfo.pPoolSizes = sizes;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateDescriptorPool(device.handle(), &poolInfo, nullptr, &pool));
  pool_ = DescriptorPool(device.handle(), pool);
  const VkDescriptorSetLayout layouts[2] = {setLayout_.get(), setLayout_.get()};
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = 2;
  allocate.pSetLayouts = layouts;
  SSLPV_VK_CHECK(vkAllocateDescriptorSets(device.handle(), &allocate, sets_));

  // Per submission: a start stamp, one after each propagation and each reduction.
  timestamps_ = TimestampQueries(device, 1 + 2 * std::uint32_t(options_.stepsPerSubmission));
  setFactors(factors);
}

void GpuPropagator::buildItems(const StepFactors& factors) {
  ItemPlan plan = planItems(frame_, factors, options_.tileRows, options_.zChunk, workerThreads(device_));
  std::vector<LpvItem> items = std::move(plan.items);
  zChunk_ = plan.zChunk;
  coveredCells_ = plan.coveredCells;
  activeCells_ = std::size_t(std::count(factors.active.begin(), factors.active.end(), 1));
  if (items.size() > device_.properties().limits.maxComputeWorkGroupCount[0])
    throw ResourceError("LPV grid needs more work items than the Vulkan device dispatches at once");

  const bool itemsChanged = items.size() != items_.size() ||
                            !std::equal(items.begin(), items.end(), items_.begin(), [](const LpvItem& a, const LpvItem& b) {
                              return a.x == b.x && a.y == b.y && a.zBegin == b.zBegin && a.zEnd == b.zEnd;
                            });
  items_ = std::move(items);
  itemCount_ = items_.size();
  const std::size_t capacity = std::max<std::size_t>(itemCount_, 1);
  if (itemBuffer_.size() < capacity * sizeof(LpvItem)) {
    itemBuffer_ = Buffer(device_, capacity * sizeof(LpvItem), kStorage, MemoryUse::Host);
    partials_ = Buffer(device_, capacity * kEnergyRowBytes, kStorage, MemoryUse::Device);
    writeDescriptors();
  }
  std::copy(items_.begin(), items_.end(), itemBuffer_.mappedAs<LpvItem>());

  // Cells outside the items must read as zero: clear whatever earlier items left there.
  if (itemsChanged) {
    VkCommandBuffer cmd = commands_.begin();
    for (const Buffer* buffer : {&tiled_[0], &tiled_[1], &tiledAccumulated_, &linearAccumulated_})
      vkCmdFillBuffer(cmd, buffer->handle(), 0, VK_WHOLE_SIZE, 0);
    toLaterReadsBarrier(cmd);
    commands_.submitAndWait();
    tiledAccumulatedClean_ = linearAccumulatedClean_ = true;
  }
}

void GpuPropagator::writeDescriptors() {
  for (int k = 0; k < 2; ++k) {
    const VkBufferView views[kBindings] = {tiledViews_[k].get(), VK_NULL_HANDLE,  VK_NULL_HANDLE,
                                           tiledAccumulatedView_.get(), factorsView_.get(), VK_NULL_HANDLE,
                                           VK_NULL_HANDLE,       VK_NULL_HANDLE,  VK_NULL_HANDLE,
                                           linearSourceView_.get(), VK_NULL_HANDLE, tiledViews_[1 - k].get()};
    const Buffer* buffers[kBindings] = {nullptr,     &tiled_[1 - k], &tiledAccumulated_, nullptr,
                                        nullptr,     &itemBuffer_,   &partials_,         &control_,
                                        &stepTotals_, nullptr,       &linearAccumulated_, nullptr};
    VkDescriptorBufferInfo infos[kBindings]{};
    VkWriteDescriptorSet writes[kBindings]{};
    for (std::uint32_t b = 0; b < kBindings; ++b) {
      VkWriteDescriptorSet& w = writes[b];
      w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      w.dstSet = sets_[k];
      w.dstBinding = b;
      w.descriptorCount = 1;
      if (kTexelBinding[b]) {
        w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        w.pTexelBufferView = &views[b];
      } else {
        infos[b] = VkDescriptorBufferInfo{buffers[b]->handle(), 0, VK_WHOLE_SIZE};
        w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w.pBufferInfo = &infos[b];
      }
    }
    vkUpdateDescriptorSets(device_.handle(), kBindings, writes, 0, nullptr);
  }
}

void GpuPropagator::setFactors(const StepFactors& factors) {
  const std::size_t cells = frame_.cellCount();
  for (int ch = 0; ch < 3; ++ch)
    if (factors.dc[ch].size() != cells || factors.linear[ch].size() != cells ||
        (!factors.retention[ch].empty() && factors.retention[ch].size() != cells) ||
        (!factors.freshGain[ch].empty() && factors.freshGain[ch].size() != cells) ||
        (!factors.conductance[ch].empty() && factors.conductance[ch].size() != cells))
      throw GpuError("GpuPropagator: step factors are not on the propagator's frame");
  if (factors.active.size() != cells || factors.rowActive.size() != std::size_t(frame_.dims.y) * frame_.dims.z)
    throw GpuError("GpuPropagator: step factors are not on the propagator's frame");
  float* out = staging_ ? stagingBuffer_.mappedAs<float>() : factors_.mappedAs<float>();
  const glm::ivec3 d = frame_.dims;
  tbb::parallel_for(0, d.z, [&](int z) {
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) {
        const std::size_t i = frame_.index(x, y, z);
        float* cell = out + tiledIndex(x, y, z) * kFactorVec4PerCell * 4;
        for (int ch = 0; ch < 3; ++ch) {
          cell[ch] = factors.dc[ch][i];
          cell[4 + ch] = factors.linear[ch][i];
          cell[8 + ch] = factors.retention[ch].empty() ? 0.0f : factors.retention[ch][i];
          cell[12 + ch] = factors.freshGain[ch].empty() ? 1.0f : factors.freshGain[ch][i];
          cell[16 + ch] = factors.conductance[ch].empty() ? 1.0f : factors.conductance[ch][i];
        }
        cell[3] = factors.active[i] ? 1.0f : 0.0f;
        cell[7] = 0.0f;
        cell[11] = 0.0f;
        cell[15] = 0.0f;
        cell[19] = 0.0f;
      }
  });
  if (staging_) {
    VkCommandBuffer cmd = commands_.begin();
    const VkBufferCopy region{0, 0, factors_.size()};
    vkCmdCopyBuffer(cmd, stagingBuffer_.handle(), factors_.handle(), 1, &region);
    commands_.submitAndWait();
  }
  active_ = factors.active;
  isotropicSteps_ = options_.isotropicSteps && keepsCellsIsotropic(factors);
  freshGain_ = factors.freshGain;
  buildItems(factors);
}

std::size_t GpuPropagator::tiledIndex(int x, int y, int z) const {
  return std::size_t(SSLPV_TILED_INDEX(std::size_t(x), std::size_t(y), std::size_t(z), std::size_t(tilesX_),
                                       std::size_t(options_.tileRows), std::size_t(frame_.dims.z)));
}

void GpuPropagator::transfer(const ShGrid* from, ShGrid* to, const Buffer& device, bool tiled, bool activeOnly) {
  const ShGrid& grid = from ? *from : *to;
  requireFrame(grid, frame_, from ? "uploaded" : "downloaded");
  if (to && staging_) {
    VkCommandBuffer cmd = commands_.begin();
    deviceWritesBarrier(cmd);
    timestamps_.reset(cmd);
    timestamps_.write(cmd, 0);
    const VkBufferCopy region{0, 0, device.size()};
    vkCmdCopyBuffer(cmd, device.handle(), stagingBuffer_.handle(), 1, &region);
    toHostBarrier(cmd);
    timestamps_.write(cmd, 1);
    commands_.submitAndWait();
    timings_.readbackMs += timestamps_.readMilliseconds(2)[1];
  }
  float* memory = staging_ ? stagingBuffer_.mappedAs<float>() : device.mappedAs<float>();
  const glm::ivec3 d = frame_.dims;
  tbb::parallel_for(0, d.z, [&](int z) {
    for (int y = 0; y < d.y; ++y)
      for (int x = 0; x < d.x; ++x) {
        const std::size_t i = frame_.index(x, y, z);
        float* cell = memory + (tiled ? tiledIndex(x, y, z) : i) * 12;  // plane = channel*4 + sh
        if (to) {
          for (int k = 0; k < ShGrid::kPlanes; ++k) to->planes[k][i] = cell[k];
        } else {
          const bool keep = !activeOnly || active_[i];
          for (int k = 0; k < ShGrid::kPlanes; ++k) cell[k] = keep ? from->planes[k][i] : 0.0f;
        }
      }
  });
  if (from && staging_) {
    VkCommandBuffer cmd = commands_.begin();
    timestamps_.reset(cmd);
    timestamps_.write(cmd, 0);
    const VkBufferCopy region{0, 0, device.size()};
    vkCmdCopyBuffer(cmd, stagingBuffer_.handle(), device.handle(), 1, &region);
    timestamps_.write(cmd, 1);
    commands_.submitAndWait();
    timings_.uploadMs += timestamps_.readMilliseconds(2)[1];
  }
}

void GpuPropagator::uploadField(const ShGrid& grid, const Buffer& target, bool activeOnly) {
  if (&target != &linearSource_ && &target != &linearAccumulated_)
    throw GpuError("GpuPropagator::uploadField: the target must be sourceField() or accumulated()");
  transfer(&grid, nullptr, target, false, activeOnly);
  if (&target == &linearAccumulated_) linearAccumulatedClean_ = false;
}

void GpuPropagator::downloadField(const Buffer& source, ShGrid& grid) {
  if (&source != &linearSource_ && &source != &linearAccumulated_)
    throw GpuError("GpuPropagator::downloadField: the source must be sourceField() or accumulated()");
  transfer(nullptr, &grid, source, false, false);
}

void GpuPropagator::downloadLastField(ShGrid& grid) { transfer(nullptr, &grid, tiled_[stepsRun() % 2], true, false); }

int GpuPropagator::stepsRun() const { return control_.mappedAs<const LpvControl>()->stepsRun; }

LpvStepPush GpuPropagator::stepPush(const PropagationOptions& options) const {
  LpvStepPush push{};
  push.dimsX = frame_.dims.x;
  push.dimsY = frame_.dims.y;
  push.dimsZ = frame_.dims.z;
  push.itemCount = int(itemCount_);
  push.autoSteps = options.autoSteps ? 1 : 0;
  push.autoTolerance = float(options.autoTolerance);
  push.autoTailTolerance = float(options.autoTailTolerance);
  return push;
}

void GpuPropagator::recordSteps(VkCommandBuffer cmd, Mode mode, int firstStep, int count,
                                const PropagationOptions& options, bool timestamps) {
  LpvStepPush push = stepPush(options);
  const auto groups = std::uint32_t(itemCount_);
  const bool chebyshev = chebyshevRun(mode, options);
  for (int s = 0; s < count; ++s) {
    const int step = firstStep + s;
    push.stepSlot = s % options_.stepsPerSubmission;
    push.initPower = mode == Mode::Device && step == 0 ? 1 : 0;
    // Every other step accumulates its sources and results. From the host, the injected
    // light (step 0's sources) is already in, so odd steps do; on the device, step 0
    // starts the accumulated grid with both, then even steps add.
    if (mode == Mode::Host) push.accumulate = step % 2 == 1 ? SSLPV_ACCUMULATE_ADD : SSLPV_ACCUMULATE_NONE;
    if (mode == Mode::Device)
      push.accumulate = step == 0 ? SSLPV_ACCUMULATE_START_FRESH : step % 2 == 0 ? SSLPV_ACCUMULATE_ADD : SSLPV_ACCUMULATE_NONE;
    if (chebyshev) {
      // Step 0 leaves its light alone in the accumulated grid (y) and makes no stop
      // decision; then the probe steps and the iterates, which accumulate nothing
      // (runChebyshev on the CPU).
      push.autoSteps = step == 0 ? 0 : 1;
      push.chebyshev = step == 0                              ? SSLPV_CHEBYSHEV_NONE
                       : step <= SSLPV_CHEBYSHEV_PROBE_STEPS ? SSLPV_CHEBYSHEV_PROBE
                                                             : SSLPV_CHEBYSHEV_ITERATE;
      push.accumulate = step == 0 ? SSLPV_ACCUMULATE_START_RESULT : SSLPV_ACCUMULATE_NONE;
    }
    // Step 0 reads the injected light, which may hold a linear band; after it, factors
    // that keep cells isotropic have left none.
    const StepKernel kernel = step == 0 || !isotropicSteps_ ? StepKernel::General
                              : chebyshev                   ? StepKernel::Chebyshev
                                                            : StepKernel::Isotropic;
    stepPipeline(kernel, push.accumulate != SSLPV_ACCUMULATE_NONE).bind(cmd, sets_[step % 2], &push, sizeof(push));
    if (groups > 0) vkCmdDispatch(cmd, groups, 1, 1);
    computeToComputeBarrier(cmd);
    if (timestamps) timestamps_.write(cmd, 1 + 2 * std::uint32_t(s));
    reducePipeline_.bind(cmd, sets_[0], &push, sizeof(push));
    vkCmdDispatch(cmd, 1, 1, 1);
    computeToComputeBarrier(cmd);
    if (timestamps) timestamps_.write(cmd, 2 + 2 * std::uint32_t(s));
  }
}

const ComputePipeline& GpuPropagator::stepPipeline(StepKernel kernel, bool accumulate) {
  if (kernel == StepKernel::General) return propagatePipelines_[accumulate];
  // The Chebyshev iterates never accumulate (their accumulated grid holds y).
  ComputePipeline& pipeline =
      kernel == StepKernel::Chebyshev ? chebyshevPipeline_ : isotropicPipelines_[accumulate];
  if (pipeline.pipeline() == VK_NULL_HANDLE) {
    const std::uint32_t chebyshev = kernel == StepKernel::Chebyshev ? 1u : 0u;
    pipeline = ComputePipeline(device_, spirv::lpv_propagate_comp(), setLayout_.get(), sizeof(LpvStepPush),
                               {std::uint32_t(options_.tileRows), accumulate && !chebyshev ? 1u : 0u, 1u, chebyshev});
  }
  return pipeline;
}

bool GpuPropagator::chebyshevRun(Mode mode, const PropagationOptions& options) const {
  return mode == Mode::Device && options.chebyshev && options.autoSteps && isotropicSteps_;
}

void GpuPropagator::recordFinish(VkCommandBuffer cmd, Mode mode, int stepLimit, const PropagationOptions& options) {
  if (itemCount_ == 0) return;
  LpvStepPush push = stepPush(options);
  push.chebyshev = chebyshevRun(mode, options) ? SSLPV_CHEBYSHEV_ITERATE : SSLPV_CHEBYSHEV_NONE;
  // The last step is missing from the accumulated grid when it did not accumulate: from
  // the host odd steps accumulate, so the last one (index stepsRun - 1) is missing when
  // stepsRun is odd and its light is in tiled_[1]; on the device even steps do, so it is
  // missing when stepsRun is even and its light is in tiled_[0]. Set k reads tiled_[k].
  push.leftoverParity = mode == Mode::Host ? 1 : 0;
  push.stepLimit = stepLimit;
  finishPipelines_[mode == Mode::Device].bind(cmd, sets_[mode == Mode::Host ? 1 : 0], &push, sizeof(push));
  vkCmdDispatch(cmd, std::uint32_t(itemCount_), 1, 1);
  computeToComputeBarrier(cmd);
}

void GpuPropagator::prepareDeviceRun(VkCommandBuffer cmd) {
  vkCmdFillBuffer(cmd, control_.handle(), 0, VK_WHOLE_SIZE, 0);  // not stopped, no steps, no power
  // The first step and the final copy write only inside the work items.
  if (!tiledAccumulatedClean_) vkCmdFillBuffer(cmd, tiledAccumulated_.handle(), 0, VK_WHOLE_SIZE, 0);
  if (!linearAccumulatedClean_) vkCmdFillBuffer(cmd, linearAccumulated_.handle(), 0, VK_WHOLE_SIZE, 0);
  tiledAccumulatedClean_ = linearAccumulatedClean_ = true;
  deviceWritesBarrier(cmd);  // injection's writes and the fills
  if (itemCount_ == 0) return;
  const LpvStepPush push = stepPush(PropagationOptions{});
  importPipeline_.bind(cmd, sets_[1], &push, sizeof(push));  // set 1 writes tiled_[0]
  vkCmdDispatch(cmd, std::uint32_t(itemCount_), 1, 1);
  computeToComputeBarrier(cmd);
}

PropagationResult GpuPropagator::execute(Mode mode, const PropagationOptions& options) {
  PropagationResult result;
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  const LpvControl& control = *control_.mappedAs<const LpvControl>();
  int recorded = 0;
  while (recorded < maxSteps && control.stopped == 0) {
    const int count = std::min(options_.stepsPerSubmission, maxSteps - recorded);
    const int stepsBefore = control.stepsRun;
    VkCommandBuffer cmd = commands_.begin();
    if (mode == Mode::Device && recorded == 0) prepareDeviceRun(cmd);
    deviceWritesBarrier(cmd);  // uploads, fills and earlier submissions
    timestamps_.reset(cmd);
    timestamps_.write(cmd, 0);
    recordSteps(cmd, mode, recorded, count, options, true);
    recordFinish(cmd, mode, maxSteps, options);
    toHostBarrier(cmd);
    commands_.submitAndWait();
    recorded += count;

    // Steps after an auto stop were no-ops: only the ones that ran count.
    const int ran = control.stepsRun - stepsBefore;
    const std::vector<double> ms = timestamps_.readMilliseconds(1 + 2 * std::uint32_t(count));
    const float* totals = stepTotals_.mappedAs<const float>();
    if (mode == Mode::Device && stepsBefore == 0 && ran > 0)
      for (int ch = 0; ch < 3; ++ch) result.initialPower[ch] = double(totals[SSLPV_ENERGY_SOURCE + ch]) * sh::kFluxPerC0;
    for (int s = 0; s < ran; ++s) {
      timings_.propagateMs += ms[1 + 2 * s] - ms[2 * s];
      timings_.reduceMs += ms[2 + 2 * s] - ms[1 + 2 * s];
      // The Chebyshev iterates' sums are not energies; the CPU records none for them.
      if (!options.recordEnergy || (chebyshevRun(mode, options) && stepsBefore + s > 0)) continue;
      const float* row = totals + std::size_t(s) * SSLPV_ENERGY_FLOATS;
      StepEnergy e;
      for (int ch = 0; ch < 3; ++ch) {
        const double emitted = row[SSLPV_ENERGY_EMITTED + ch];
        const double gathered = double(row[SSLPV_ENERGY_GATHERED + ch]) * sh::kFluxPerC0;
        e.inGrid[ch] = double(row[SSLPV_ENERGY_IN_GRID + ch]) * sh::kFluxPerC0;
        e.left[ch] = emitted - gathered;
        e.absorbed[ch] = double(row[SSLPV_ENERGY_ABSORBED + ch]) * sh::kFluxPerC0;
        e.clampRemoved[ch] = row[SSLPV_ENERGY_CLAMP_REMOVED + ch];
      }
      result.energy.push_back(e);
    }
  }
  result.stepsRun = control.stepsRun;
  result.capped = options.autoSteps && control.stopped == 0;
  result.tailScale = glm::dvec3(control.tailScaleR, control.tailScaleG, control.tailScaleB);
  timings_.steps = result.stepsRun;
  return result;
}

PropagationResult GpuPropagator::run(ShGrid& field, ShGrid& accumulated, const PropagationOptions& options) {
  requireFrame(field, frame_, "field");
  requireFrame(accumulated, frame_, "accumulated");
  timings_ = GpuPropagationTimings{};
  const glm::dvec3 initialPower = gridPower(field);
  // The injected light counts as step 0 of the sum, exactly as on the CPU.
  const bool stepping = propagationSteps(frame_, options);
  addInjected(stepping ? freshGain_ : std::array<std::vector<float>, 3>{}, field, accumulated);
  if (!stepping) {
    PropagationResult result;
    result.initialPower = initialPower;
    return result;
  }

  transfer(&field, nullptr, tiled_[0], true, true);
  transfer(&accumulated, nullptr, tiledAccumulated_, true, false);
  tiledAccumulatedClean_ = false;
  LpvControl& control = *control_.mappedAs<LpvControl>();
  control = LpvControl{};
  control.accumulatedPowerR = float(initialPower.x);
  control.accumulatedPowerG = float(initialPower.y);
  control.accumulatedPowerB = float(initialPower.z);
  control.previousInGridR = float(initialPower.x);
  control.previousInGridG = float(initialPower.y);
  control.previousInGridB = float(initialPower.z);
  PropagationResult result = execute(Mode::Host, options);
  result.initialPower = initialPower;
  transfer(nullptr, &field, tiled_[result.stepsRun % 2], true, false);
  transfer(nullptr, &accumulated, tiledAccumulated_, true, false);
  return result;
}

PropagationResult GpuPropagator::runOnDevice(const PropagationOptions& options) {
  timings_ = GpuPropagationTimings{};
  *control_.mappedAs<LpvControl>() = LpvControl{};  // the host loop reads it before the GPU resets it
  if (!propagationSteps(frame_, options)) {
    VkCommandBuffer cmd = commands_.begin();
    record(cmd, options);
    commands_.submitAndWait();
    return PropagationResult{};
  }
  return execute(Mode::Device, options);
}

void GpuPropagator::record(VkCommandBuffer cmd, const PropagationOptions& options) {
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  prepareDeviceRun(cmd);
  if (!propagationSteps(frame_, options)) {
    // No step: the accumulated light is the injected light, wherever it is.
    const VkBufferCopy region{0, 0, linearAccumulated_.size()};
    vkCmdCopyBuffer(cmd, linearSource_.handle(), linearAccumulated_.handle(), 1, &region);
    linearAccumulatedClean_ = false;
  } else {
    recordSteps(cmd, Mode::Device, 0, maxSteps, options, false);
    recordFinish(cmd, Mode::Device, maxSteps, options);
  }
  toLaterReadsBarrier(cmd);
}

}  // namespace sslpv::gpu

#include "gpu/gpu_propagation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <string>

#include "volume/error.h"
#include "volume/sh.h"

namespace sslpv::gpu {
namespace {

constexpr std::uint32_t kBindings = 7;  // see the bindings of shaders/lpv_propagate.comp
constexpr VkDeviceSize kVec4 = 4 * sizeof(float);
constexpr VkDeviceSize kFieldVec4PerCell = 3;   // one vec4 of (c0, c1x, c1y, c1z) per channel
constexpr VkDeviceSize kFactorVec4PerCell = 2;  // (dc.rgb, active), (linear.rgb, 0)
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

glm::dvec3 gridPower(const ShGrid& grid) {
  glm::dvec3 power(0.0);
  for (int ch = 0; ch < 3; ++ch) {
    double sum = 0.0;
    for (float c0 : grid.planes[ch * 4]) sum += c0;
    power[ch] = sum * sh::kFluxPerC0;
  }
  return power;
}

void requireFrame(const ShGrid& grid, const GridFrame& frame, const char* what) {
  if (grid.frame.dims != frame.dims)
    throw GpuError(std::string("GpuPropagator::run: ") + what + " grid is not on the propagator's frame");
  for (const std::vector<float>& plane : grid.planes)
    if (plane.size() != frame.cellCount())
      throw GpuError(std::string("GpuPropagator::run: ") + what + " grid planes do not match its frame");
}

/// Cells along z per workgroup: enough workgroups for every core of the device (lavapipe
/// runs one workgroup per thread), but long columns, since each chunk reloads 2 slices.
int autoZChunk(const VulkanDevice& device, int groupsXY, int dimsZ) {
  const int wanted = device.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 16 : 256;
  const int chunks = std::clamp(wanted / std::max(1, groupsXY), 1, std::max(1, dimsZ / 8));
  return (dimsZ + chunks - 1) / chunks;
}

}  // namespace

GpuPropagator::GpuPropagator(const VulkanDevice& device, const GridFrame& frame, const StepFactors& factors,
                             const GpuPropagatorOptions& options)
    : device_(device), frame_(frame), options_(options), commands_(device) {
  const VkPhysicalDeviceLimits& limits = device.properties().limits;
  const auto sharedBytes = [](int x, int y) { return std::uint64_t(x + 2) * (y + 2) * 3 * kVec4; };
  if (options_.groupX <= 0 || options_.groupY <= 0) {
    // Wide rows make long contiguous runs in memory; lanes past the grid's edge would idle.
    options_.groupX = 8;
    while (options_.groupX < 64 && options_.groupX < frame.dims.x) options_.groupX *= 2;
    options_.groupY = std::max(4, 128 / options_.groupX);
    while (options_.groupX > 8 && sharedBytes(options_.groupX, options_.groupY) > limits.maxComputeSharedMemorySize) {
      options_.groupX /= 2;
      options_.groupY = std::max(4, 128 / options_.groupX);
    }
  }
  const int groupX = options_.groupX, groupY = options_.groupY;
  if (groupX < 4 || groupY < 4 || options.stepsPerSubmission < 1)
    throw GpuError("GpuPropagatorOptions: workgroups need x, y >= 4 and stepsPerSubmission >= 1");
  if (sharedBytes(groupX, groupY) > limits.maxComputeSharedMemorySize ||
      std::uint64_t(groupX) * groupY > limits.maxComputeWorkGroupInvocations)
    throw GpuError("GpuPropagatorOptions: workgroup " + std::to_string(groupX) + "x" + std::to_string(groupY) +
                   " exceeds the device's compute limits");

  const std::size_t cells = frame.cellCount();
  const VkDeviceSize fieldBytes = std::max<VkDeviceSize>(cells, 1) * kFieldVec4PerCell * kVec4;
  if (fieldBytes > limits.maxStorageBufferRange)
    throw ResourceError("LPV grid " + std::to_string(frame.dims.x) + "x" + std::to_string(frame.dims.y) + "x" +
                        std::to_string(frame.dims.z) + " needs " + std::to_string(fieldBytes >> 20) +
                        " MiB per light field, more than the Vulkan device's storage-buffer range of " +
                        std::to_string(limits.maxStorageBufferRange >> 20) + " MiB");

  const auto groupsAlong = [](int count, int perGroup) {
    return std::uint32_t((std::max(1, count) + perGroup - 1) / perGroup);
  };
  groups_[0] = groupsAlong(frame.dims.x, groupX);
  groups_[1] = groupsAlong(frame.dims.y, groupY);
  zChunk_ =
      options.zChunk > 0 ? options.zChunk : autoZChunk(device, int(groups_[0] * groups_[1]), std::max(1, frame.dims.z));
  groups_[2] = std::uint32_t((std::max(1, frame.dims.z) + zChunk_ - 1) / zChunk_);
  for (int axis = 0; axis < 3; ++axis)
    if (groups_[axis] > limits.maxComputeWorkGroupCount[axis])
      throw ResourceError("LPV grid needs more workgroups than the Vulkan device dispatches");
  partialRows_ = groups_[0] * groups_[1] * groups_[2];  // one row of power sums per workgroup

  setLayout_ = makeStorageBufferSetLayout(device, kBindings);
  propagatePipeline_ = ComputePipeline(device, spirv::lpv_propagate_comp(), setLayout_.get(), sizeof(LpvStepPush),
                                       {std::uint32_t(groupX), std::uint32_t(groupY)});
  reducePipeline_ = ComputePipeline(device, spirv::lpv_reduce_comp(), setLayout_.get(), sizeof(LpvStepPush));
  accumulatePipeline_ = ComputePipeline(device, spirv::lpv_accumulate_comp(), setLayout_.get(), sizeof(LpvStepPush));

  for (Buffer& field : fields_) field = Buffer(device, fieldBytes, kStorage, MemoryUse::Device);
  accumulated_ = Buffer(device, fieldBytes, kStorage, MemoryUse::Device);
  factors_ = Buffer(device, std::max<VkDeviceSize>(cells, 1) * kFactorVec4PerCell * kVec4, kStorage, MemoryUse::Device);
  partials_ =
      Buffer(device, VkDeviceSize(partialRows_) * SSLPV_ENERGY_FLOATS * sizeof(float), kStorage, MemoryUse::Device);
  control_ = Buffer(device, sizeof(LpvControl), kStorage, MemoryUse::Host);
  stepTotals_ = Buffer(device, VkDeviceSize(options.stepsPerSubmission) * SSLPV_ENERGY_FLOATS * sizeof(float), kStorage,
                       MemoryUse::Host);
  staging_ = options.forceStaging || !fields_[0].mapped() || !accumulated_.mapped() || !factors_.mapped();
  if (staging_) stagingBuffer_ = Buffer(device, fieldBytes, kStorage, MemoryUse::Host);

  sets_ = StorageBufferSets(device, setLayout_.get(), kBindings, 2);
  for (std::size_t k = 0; k < 2; ++k) {
    sets_.write(k, 0, fields_[k]);
    sets_.write(k, 1, fields_[1 - k]);
    sets_.write(k, 2, accumulated_);
    sets_.write(k, 3, factors_);
    sets_.write(k, 4, partials_);
    sets_.write(k, 5, control_);
    sets_.write(k, 6, stepTotals_);
  }
  // Per submission: a start stamp, then one after each propagation and each reduction.
  timestamps_ = TimestampQueries(device, 1 + 2 * std::uint32_t(options.stepsPerSubmission));
  setFactors(factors);
}

void GpuPropagator::setFactors(const StepFactors& factors) {
  const std::size_t cells = frame_.cellCount();
  for (int ch = 0; ch < 3; ++ch)
    if (factors.dc[ch].size() != cells || factors.linear[ch].size() != cells)
      throw GpuError("GpuPropagator: step factors are not on the propagator's frame");
  if (factors.active.size() != cells) throw GpuError("GpuPropagator: step factors are not on the propagator's frame");
  float* out = staging_ ? stagingBuffer_.mappedAs<float>() : factors_.mappedAs<float>();
  tbb::parallel_for(std::size_t(0), cells, [&](std::size_t i) {
    float* cell = out + i * kFactorVec4PerCell * 4;
    for (int ch = 0; ch < 3; ++ch) {
      cell[ch] = factors.dc[ch][i];
      cell[4 + ch] = factors.linear[ch][i];
    }
    cell[3] = factors.active[i] ? 1.0f : 0.0f;
    cell[7] = 0.0f;
  });
  if (staging_) {
    VkCommandBuffer cmd = commands_.begin();
    const VkBufferCopy region{0, 0, factors_.size()};
    vkCmdCopyBuffer(cmd, stagingBuffer_.handle(), factors_.handle(), 1, &region);
    commands_.submitAndWait();
  }
}

void GpuPropagator::upload(const ShGrid& grid, const Buffer& target) {
  float* out = staging_ ? stagingBuffer_.mappedAs<float>() : target.mappedAs<float>();
  const std::size_t cells = frame_.cellCount();
  tbb::parallel_for(std::size_t(0), cells, [&](std::size_t i) {
    for (int k = 0; k < ShGrid::kPlanes; ++k) out[i * 12 + k] = grid.planes[k][i];  // plane = channel*4 + sh
  });
  if (staging_) {
    VkCommandBuffer cmd = commands_.begin();
    timestamps_.reset(cmd);
    timestamps_.write(cmd, 0);
    const VkBufferCopy region{0, 0, target.size()};
    vkCmdCopyBuffer(cmd, stagingBuffer_.handle(), target.handle(), 1, &region);
    timestamps_.write(cmd, 1);
    commands_.submitAndWait();
    timings_.uploadMs += timestamps_.readMilliseconds(2)[1];
  }
}

void GpuPropagator::download(const Buffer& source, ShGrid& grid) {
  if (staging_) {
    VkCommandBuffer cmd = commands_.begin();
    deviceWritesBarrier(cmd);
    timestamps_.reset(cmd);
    timestamps_.write(cmd, 0);
    const VkBufferCopy region{0, 0, source.size()};
    vkCmdCopyBuffer(cmd, source.handle(), stagingBuffer_.handle(), 1, &region);
    toHostBarrier(cmd);
    timestamps_.write(cmd, 1);
    commands_.submitAndWait();
    timings_.readbackMs += timestamps_.readMilliseconds(2)[1];
  }
  const float* in = staging_ ? stagingBuffer_.mappedAs<const float>() : source.mappedAs<const float>();
  tbb::parallel_for(std::size_t(0), frame_.cellCount(), [&](std::size_t i) {
    for (int k = 0; k < ShGrid::kPlanes; ++k) grid.planes[k][i] = in[i * 12 + k];
  });
}

LpvStepPush GpuPropagator::stepPush(const PropagationOptions& options) const {
  LpvStepPush push{};
  push.dimsX = frame_.dims.x;
  push.dimsY = frame_.dims.y;
  push.dimsZ = frame_.dims.z;
  push.zChunk = zChunk_;
  push.partialRows = int(partialRows_);
  push.autoSteps = options.autoSteps ? 1 : 0;
  push.autoTolerance = float(options.autoTolerance);
  return push;
}

void GpuPropagator::recordSteps(VkCommandBuffer cmd, int firstStep, int count, const PropagationOptions& options) {
  LpvStepPush push = stepPush(options);
  deviceWritesBarrier(cmd);  // uploads, fills and earlier steps
  timestamps_.reset(cmd);
  timestamps_.write(cmd, 0);
  for (int s = 0; s < count; ++s) {
    const int step = firstStep + s;
    push.stepSlot = s;
    // Odd steps accumulate their sources and results: step 0's sources (the injected
    // light) are already in, and accumulateLastStep() adds a result left over at the end.
    push.accumulate = step % 2;
    propagatePipeline_.bind(cmd, sets_.set(std::size_t(step) % 2), &push, sizeof(push));
    vkCmdDispatch(cmd, groups_[0], groups_[1], groups_[2]);
    computeToComputeBarrier(cmd);
    timestamps_.write(cmd, 1 + 2 * std::uint32_t(s));
    reducePipeline_.bind(cmd, sets_.set(0), &push, sizeof(push));
    vkCmdDispatch(cmd, 1, 1, 1);
    computeToComputeBarrier(cmd);
    timestamps_.write(cmd, 2 + 2 * std::uint32_t(s));
  }
  toHostBarrier(cmd);
}

void GpuPropagator::accumulateLastStep(int stepsRun) {
  if (stepsRun % 2 == 0) return;  // the last step (odd index) accumulated itself
  const LpvStepPush push = stepPush(PropagationOptions{});
  VkCommandBuffer cmd = commands_.begin();
  deviceWritesBarrier(cmd);
  // Set k reads fields_[k % 2], which after stepsRun steps holds the last result.
  accumulatePipeline_.bind(cmd, sets_.set(std::size_t(stepsRun) % 2), &push, sizeof(push));
  vkCmdDispatch(cmd, std::uint32_t((frame_.cellCount() + 63) / 64), 1, 1);
  toHostBarrier(cmd);
  commands_.submitAndWait();
}

PropagationResult GpuPropagator::run(ShGrid& field, ShGrid& accumulated, const PropagationOptions& options) {
  requireFrame(field, frame_, "field");
  requireFrame(accumulated, frame_, "accumulated");
  timings_ = GpuPropagationTimings{};
  PropagationResult result;
  result.initialPower = gridPower(field);
  // The injected light counts as step 0 of the sum, exactly as on the CPU.
  for (int k = 0; k < ShGrid::kPlanes; ++k)
    std::transform(accumulated.planes[k].begin(), accumulated.planes[k].end(), field.planes[k].begin(),
                   accumulated.planes[k].begin(), std::plus<float>());
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  if (frame_.dims.x < 3 || frame_.dims.y < 3 || frame_.dims.z < 3 || maxSteps <= 0) return result;

  upload(field, fields_[0]);
  upload(accumulated, accumulated_);
  // The first step writes only interior cells of fields_[1]: the rest must read as zero,
  // as the CPU's freshly allocated grid does.
  {
    VkCommandBuffer cmd = commands_.begin();
    vkCmdFillBuffer(cmd, fields_[1].handle(), 0, VK_WHOLE_SIZE, 0);
    commands_.submitAndWait();
  }
  LpvControl& control = *control_.mappedAs<LpvControl>();
  control = LpvControl{};
  control.accumulatedPowerR = float(result.initialPower.x);
  control.accumulatedPowerG = float(result.initialPower.y);
  control.accumulatedPowerB = float(result.initialPower.z);

  int recorded = 0;
  while (recorded < maxSteps && control.stopped == 0) {
    const int count = std::min(options_.stepsPerSubmission, maxSteps - recorded);
    const int stepsBefore = control.stepsRun;
    recordSteps(commands_.begin(), recorded, count, options);
    commands_.submitAndWait();
    recorded += count;

    // Steps after an auto stop were no-ops: only the ones that ran count.
    const int ran = control.stepsRun - stepsBefore;
    const std::vector<double> ms = timestamps_.readMilliseconds(1 + 2 * std::uint32_t(count));
    const float* totals = stepTotals_.mappedAs<const float>();
    for (int s = 0; s < ran; ++s) {
      timings_.propagateMs += ms[1 + 2 * s] - ms[2 * s];
      timings_.reduceMs += ms[2 + 2 * s] - ms[1 + 2 * s];
      if (!options.recordEnergy) continue;
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
  timings_.steps = result.stepsRun;
  accumulateLastStep(result.stepsRun);

  download(fields_[result.stepsRun % 2], field);
  download(accumulated_, accumulated);
  return result;
}

}  // namespace sslpv::gpu

#pragma once
// Shadow maps on the GPU by rasterization: the twin of sslpv::castShadowMap
// (volume/cpu/shadow_map.cpp). Views are planned by the same planShadowViews
// (volume/scene/shadow_view.h), so both cast the same texel rays. Per view, the mesh is
// rasterized into a triangle-id image (pixel centres = texel rays, nearest surface by a
// depth test); a compute resolve then intersects each texel's exact ray with its
// triangle (or, where vertex snapping put the texel on the wrong side of an edge, with
// the neighbour the ray crosses: shaders/ray_triangle_pick.glsl) and writes one GpuFluxSample per texel (device_shared/flux_sample_shared.h) into one
// device buffer, all views of all lights concatenated, misses included (w = 0).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/passes/gpu_mesh.h"
#include "gpu/vk/graphics.h"
#include "device_shared/flux_sample_shared.h"
#include "device_shared/shadow_map_shared.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/shadow_view.h"

namespace sslpv::gpu {

/// Where one light's texels sit in GpuShadowMapper::samples().
struct GpuShadowLight {
  std::uint32_t firstSample = 0;  ///< index of the light's first texel record
  std::uint32_t sampleCount = 0;  ///< views * size² (0 when culled)
  std::uint32_t firstView = 0;    ///< index into GpuShadowMapper::views()
  std::uint32_t viewCount = 0;
  bool culled = false;  ///< planShadowViews returned no view
};

/// Casts the shadow maps of a set of lights over one mesh. Constructed once per object;
/// setLights() when the lights, the index of refraction or the mesh's positions
/// (GpuMesh::updatePositions: the views are planned around its bounds) change,
/// record()/run() per frame.
/// One recording in flight at a time (setLights rewrites buffers the recording reads).
class GpuShadowMapper {
 public:
  /// `device` and `mesh` must outlive the mapper; `size` is the texels per map side.
  /// Throws GpuError without Vulkan 1.3 (dynamic rendering) or for size < 1.
  GpuShadowMapper(const VulkanDevice& device, const GpuMesh& mesh, int size);

  /// Plans every light's views (around mesh.bounds(), as castShadowMap does around the
  /// mesh's bounds), uploads them and sizes the sample buffer. The device must not be
  /// executing a recording of this mapper.
  void setLights(const std::vector<Light>& lights, double ior);

  /// Records all views: rasterize, copy the triangle ids out, resolve into samples().
  /// Starts with a barrier after earlier transfer/compute/fragment work (so the previous
  /// frame's readers of samples() are done) and ends with one making samples() visible
  /// to later compute shaders and transfers. When `timestamps` is given, writes
  /// timestamps `firstQuery` (start) and `firstQuery + 1` (end); the caller resets them.
  void record(VkCommandBuffer cmd, TimestampQueries* timestamps = nullptr, std::uint32_t firstQuery = 0) const;

  /// record() in the mapper's own command buffer, submit, wait (samples() then visible
  /// to the host); returns the GPU milliseconds between the two timestamps (0 without
  /// timestamps).
  double run();

  const Buffer& samples() const { return samples_; }
  /// One GpuShadowView per view of every light, in views() order.
  const Buffer& viewRecords() const { return viewRecords_; }
  /// Records in samples(): every texel of every view (hits and misses).
  std::uint32_t sampleCount() const { return sampleCount_; }
  int size() const { return size_; }
  const std::vector<ShadowView>& views() const { return views_; }
  const std::vector<GpuShadowLight>& lights() const { return lights_; }

  /// The sample records, read back (after a run() or an executed recording whose
  /// writes were made visible to the host).
  std::vector<GpuFluxSample> readSamples() const;
  /// Per light, the statistics castShadowMap reports: texels, hits, incident power
  /// (the light's I or E times each hit texel's ShadowView::texelRay weight, in double)
  /// and transmitted power (sum of the records' flux), culled. From readSamples().
  std::vector<ShadowMapStats> stats(const std::vector<GpuFluxSample>& samples) const;

 private:
  const VulkanDevice& device_;
  const GpuMesh& mesh_;
  int size_;
  std::vector<Light> lightList_;
  std::vector<ShadowView> views_;
  std::vector<GpuShadowLight> lights_;
  std::uint32_t sampleCount_ = 0;

  DescriptorSetLayout setLayout_;
  GraphicsPipeline rasterPipeline_;
  ComputePipeline resolvePipeline_;
  StorageBufferSets sets_;
  Image2D triangleImage_, depthImage_;
  // rasterIds_: what the rasterizer saw per texel; triangleIds_: what the resolve found the
  // texel's ray crosses (separate, so the resolve reads neighbours' raster ids race-free).
  Buffer viewRecords_, rasterIds_, triangleIds_, samples_;
  CommandContext commands_;
  TimestampQueries timestamps_;
};

}  // namespace sslpv::gpu

#pragma once
// Shading on the GPU by rasterization: the twin of sslpv::shadeImage (volume/cpu/shade.cpp).
// The mesh is rasterized from the camera (pixel centres are the CPU's camera rays) into a
// triangle-id image with a depth test; a compute pass then shades every pixel once: its
// camera ray meets the triangle it crosses (the rasterized one, or the neighbour the
// exact ray crosses where vertex snapping picked the wrong side of an edge), the accumulated LPV is read half a cell inside
// the surface (a full cell when no active cell is near) with the coverage-weighted
// active trilinear weights (shaders/cell_coverage.glsl), and radiance
// T(θo)/η² · (1/(Aπ)) ∫_H I(ω) dω goes into an RGBA32F buffer (alpha 1 where the surface
// is, background 0). Shading in the fragment shader instead measured about 3x slower on
// llvmpipe (220 against 72 ms at 512², 20K triangles, on a loaded 2-core machine), which
// runs a whole 4x4 block of fragments for each small triangle it touches.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/passes/gpu_mesh.h"
#include "gpu/vk/graphics.h"
#include "device_shared/shade_shared.h"
#include "volume/calibration/exit_law.h"
#include "volume/core/image_io.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/scene.h"

#include "volume/lpv/lpv_stages.h"

namespace sslpv::gpu {

/// A new device storage buffer holding `grid` in GpuPropagator's layout (3 vec4 per cell,
/// one per channel: (c0, c1x, c1y, c1z), x fastest), e.g. a CPU-accumulated field for
/// shading, and for tests.
Buffer uploadLightField(const VulkanDevice& device, const ShGrid& grid);

/// A new device storage buffer with two vec4 per cell (binding 7 of shaders/shade.comp):
/// (StepFactors::exitGain rgb, 0), the per-cell radiance gain, and
/// (StepFactors::reducedAlbedo rgb, 1) selecting the cell's exit angular shape, or
/// (0, 0, 0, 0) when the factors have no reduced albedo (seed scheme: no exit law).
Buffer uploadExitFactors(const VulkanDevice& device, const StepFactors& factors, const GridFrame& frame);

/// A new device storage buffer holding `table.shape` (binding 8 of shaders/shade.comp):
/// upload once per η; shadeImage's exitLawTable(ior) on the CPU side.
Buffer uploadExitLaw(const VulkanDevice& device, const ExitLawTable& table);

/// A new device storage buffer with two vec4 per cell (binding 9 of shaders/shade.comp):
/// (σt − g σs rgb, 0) and ((1 − g) σs rgb, 0), the similarity relation's reduced
/// extinction and scattering the single-scattering term reads.
Buffer uploadReducedMedium(const VulkanDevice& device, const MaterialGrid& material);

/// What the single-scattering term (volume/cpu/single_scattering.h) reads: uploadReducedMedium()
/// of the material, and a GpuShadowMapper's view records and texel records after its run.
struct GpuSingleScattering {
  const Buffer* medium = nullptr;
  const Buffer* views = nullptr;
  const Buffer* samples = nullptr;
  std::uint32_t viewCount = 0;
};

/// Shades one camera view of one mesh. Constructed once per object and image size;
/// record()/shade() per frame. One recording in flight at a time (record() rewrites the
/// descriptor set).
class GpuShader {
 public:
  /// `device` and `mesh` must outlive the shader. Throws GpuError without Vulkan 1.3
  /// (dynamic rendering) or for an image size the device cannot render.
  GpuShader(const VulkanDevice& device, const GpuMesh& mesh, int width, int height);

  /// Records the shading pass into radiance(). `accumulated`: the accumulated light field
  /// of `frame` in GpuPropagator's layout; `cellCoverage`: uploadCellCoverage()
  /// (gpu/passes/gpu_inject.h) of the material on `frame`; `exitFactors`: uploadExitFactors();
  /// `exitLaw`: uploadExitLaw(exitLawTable(ior)); `single`: the single-scattering term's
  /// inputs (null: no such term, as the seed scheme shades). Starts with a barrier making earlier compute and
  /// transfer writes (propagation) visible to the pass, and ends with one making
  /// radiance() visible to transfers, compute shaders and the host. The camera must have
  /// the shader's width and height. With `timestamps`, writes `firstQuery` (start) and
  /// `firstQuery + 1` (end); the caller resets them.
  void record(VkCommandBuffer cmd, const Camera& camera, const Buffer& accumulated, const Buffer& cellCoverage,
              const Buffer& exitFactors, const Buffer& exitLaw, const GridFrame& frame, double ior,
              TimestampQueries* timestamps = nullptr, std::uint32_t firstQuery = 0,
              const GpuSingleScattering* single = nullptr);

  /// record() plus a copy into host memory, submitted and waited for; the image as
  /// shadeImage returns it (row 0 at the top, background 0).
  Image shade(const Camera& camera, const Buffer& accumulated, const Buffer& cellCoverage, const Buffer& exitFactors,
              const Buffer& exitLaw, const GridFrame& frame, double ior, const GpuSingleScattering* single = nullptr);

  /// GPU milliseconds of the shading pass in the last shade() (0 without timestamps).
  double lastShadeMs() const { return lastShadeMs_; }
  /// The shaded image: std430 vec4 per pixel, row 0 at the top, x fastest; (radiance, 1)
  /// on the surface, (0, 0, 0, 0) on the background. copyBufferToImage (gpu/vk/graphics.h)
  /// puts it into an R32G32B32A32_SFLOAT image for display.
  const Buffer& radiance() const { return radiance_; }
  /// Per pixel, the 1-based index of the triangle seen there (0: background), from the
  /// last executed recording: the one the pixel's exact ray crosses (the rasterized
  /// triangle or, within the rasterizer's snapping of an edge, its neighbour), i.e. the
  /// triangle that was shaded (picking, tests).
  std::vector<std::uint32_t> readTriangles() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  const VulkanDevice& device_;
  const GpuMesh& mesh_;
  int width_, height_;
  DescriptorSetLayout setLayout_;
  GraphicsPipeline rasterPipeline_;
  ComputePipeline shadePipeline_;
  StorageBufferSets sets_;
  Image2D triangleImage_, depthImage_;
  Buffer triangleIds_, radiance_;
  CommandContext commands_;
  TimestampQueries timestamps_;
  double lastShadeMs_ = 0.0;
};

}  // namespace sslpv::gpu

#pragma once
// The CPU/Vulkan image agreement every GPU agreement test asserts (gpu_agreement_test.cpp
// states the tolerances and why), for one scene and optionally a painted material set.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <optional>

#include "gpu/vulkan_renderer.h"
#include "image_agreement.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/material/material_set.h"
#include "volume/scene/mesh.h"
#include "volume/scene/ray_scene.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"

namespace sslpv::test {

/// Mean over the lit pixels, all channels.
inline double meanLitRadiance(const Image& image) {
  double sum = 0.0;
  std::size_t lit = 0;
  for (const glm::vec3& p : image.pixels)
    if (p != glm::vec3(0.0f)) {
      sum += (p.x + p.y + p.z) / 3.0;
      ++lit;
    }
  return lit ? sum / double(lit) : 0.0;
}

/// Renders `scene` (with `set` painted in when given) on both backends and expects the
/// images to agree: mean relative difference <= 1 %, every interior pixel within 2 %
/// (relative to max(cpu, 1e-3 x the mean)), edge pixels <= 1 % and background mismatches
/// <= 0.1 % of the object, the same occupied cells, no surface mismatch.
/// With `moveTo` (a deforming scene), both renderers first render a frame at scene.time,
/// then setTime(*moveTo), and that second frame is compared.
inline void expectGpuAgreement(const Scene& scene, const gpu::VulkanDevice& device,
                               std::shared_ptr<const MaterialSet> set = nullptr,
                               std::optional<double> moveTo = std::nullopt) {
  CpuRenderer cpu(scene);
  gpu::VulkanRenderer vulkan(scene, device);
  if (set) {
    cpu.setMaterialSet(set, std::nullopt);
    vulkan.setMaterialSet(set, std::nullopt);
  }
  RenderReport cpuReport, gpuReport;
  if (moveTo) {
    cpu.render(scene.lpv);
    vulkan.render(scene.lpv);
    cpu.setTime(*moveTo);
    vulkan.setTime(*moveTo);
  }
  const Image cpuImage = cpu.render(scene.lpv, &cpuReport);
  const Image gpuImage = vulkan.render(scene.lpv, &gpuReport);
  ASSERT_EQ(cpuImage.pixels.size(), gpuImage.pixels.size());
  // The surface as posed (a deforming scene's mesh is not the file's).
  Scene posed = moveTo ? sceneAtTime(scene, *moveTo) : scene;
  posed.material.vdb.reset();
  const RayScene rays(SceneObject(posed).mesh());
  const ImageAgreement a = compareImages(gpuImage, cpuImage, vulkan.readTriangles(), cpuTriangles(scene.camera, rays),
                                         1e-3 * meanLitRadiance(cpuImage));
  char line[400];
  std::snprintf(line, sizeof line,
                "%s: %zu object pixels (%zu silhouette, %zu edge), mean relative %.3g %%, worst interior %.3g %% "
                "at (%d, %d), background mismatches %zu, surface mismatches %zu",
                scene.file.filename().string().c_str(), a.objectPixels, a.silhouette, a.edge, 100.0 * a.meanRelative,
                100.0 * a.worstInterior, a.worstX, a.worstY, a.backgroundMismatches, a.surfaceMismatches);
  std::printf("%s\n", line);
  SCOPED_TRACE(line);
  ASSERT_GT(a.interior, cpuImage.pixels.size() / 100) << "the object must be in view, or nothing is compared";
  EXPECT_EQ(gpuReport.activeCells, cpuReport.activeCells) << "both backends must see the same occupied cells";
  EXPECT_LE(a.meanRelative, 0.01);
  // Measured 2026-12-04 over the examples and 32 random scenes: worst interior pixel
  // 0.74 % (skin_sphere). It was up to 14.5 % while the GPU shadow map dropped silhouette
  // texels the rasterizer snapped out (ASilhouetteTexelTheRasterizerLeavesEmpty...).
  EXPECT_LE(a.worstInterior, 0.02);
  EXPECT_LE(double(a.edge), 0.01 * double(a.objectPixels));
  EXPECT_LE(double(a.backgroundMismatches), 0.001 * double(a.objectPixels));
  EXPECT_EQ(a.surfaceMismatches, 0u);
}

}  // namespace sslpv::test

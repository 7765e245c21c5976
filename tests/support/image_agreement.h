#pragma once
// Comparing a GPU image with its CPU twin pixel by pixel, knowing which triangle each
// pixel shows on both sides. Pixel classes: background = all channels exactly 0;
// silhouette = a background pixel in the 3x3 neighbourhood in either image (the outline
// may move by a pixel between rasterizer and ray caster); edge = both see a surface but
// not the same triangle (the pixel centre lies within the rasterizer's vertex snapping
// of a shared edge; across a crease the normals differ, so does the radiance);
// interior = every other object pixel.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <vector>

#include "volume/core/image_io.h"
#include "volume/scene/ray_scene.h"
#include "volume/scene/scene.h"

namespace sslpv::test {

inline bool isBackground(const Image& image, int x, int y) { return image.at(x, y) == glm::vec3(0.0f); }

/// Per pixel, the first hit of the camera ray of shadeImage (volume/cpu/shade.cpp, whose ray
/// set-up this repeats).
inline std::vector<RayHit> cpuHits(const Camera& camera, const RayScene& rays) {
  const glm::dvec3 forward = glm::normalize(camera.target - camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalfY = std::tan(glm::radians(0.5 * camera.fovYDeg));
  const double tanHalfX = tanHalfY * camera.width / camera.height;
  const std::size_t pixels = std::size_t(camera.width) * std::size_t(camera.height);
  std::vector<glm::vec3> origins(pixels, glm::vec3(camera.position)), dirs(pixels);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const double u = (2.0 * (x + 0.5) / camera.width - 1.0) * tanHalfX;
      const double v = (1.0 - 2.0 * (y + 0.5) / camera.height) * tanHalfY;
      dirs[std::size_t(y) * camera.width + x] = glm::vec3(glm::normalize(forward + u * right + v * up));
    }
  std::vector<RayHit> hits(pixels);
  rays.intersectMany(origins.data(), dirs.data(), hits.data(), pixels);
  return hits;
}

/// Per pixel, the 1-based triangle the camera ray of shadeImage hits first, 0 for none.
inline std::vector<std::uint32_t> cpuTriangles(const Camera& camera, const RayScene& rays) {
  const std::vector<RayHit> hits = cpuHits(camera, rays);
  std::vector<std::uint32_t> triangles(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) triangles[i] = hits[i].hit ? hits[i].triangle + 1 : 0;
  return triangles;
}

struct ImageAgreement {
  std::size_t objectPixels = 0, silhouette = 0, interior = 0, edge = 0, backgroundMismatches = 0;
  std::size_t surfaceMismatches = 0;  ///< triangle 0 on one side only, off the silhouette
  double meanRelative = 0.0, worstInterior = 0.0;
  int worstX = -1, worstY = -1;
};

/// `darkFloor`: relative differences are taken against max(|cpu|, darkFloor), so that a
/// pixel the light barely reaches (1e-9 against 2e-9) is not a "100 %" difference.
inline ImageAgreement compareImages(const Image& gpu, const Image& cpu, const std::vector<std::uint32_t>& gpuTriangles,
                                    const std::vector<std::uint32_t>& cpuTriangles, double darkFloor = 1e-30) {
  ImageAgreement a;
  double sumRelative = 0.0;
  for (int y = 0; y < cpu.height; ++y)
    for (int x = 0; x < cpu.width; ++x) {
      bool anyBackground = false, allCpuBackground = true, allGpuBackground = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = std::clamp(x + dx, 0, cpu.width - 1), ny = std::clamp(y + dy, 0, cpu.height - 1);
          const bool c = isBackground(cpu, nx, ny), g = isBackground(gpu, nx, ny);
          anyBackground |= c || g;
          allCpuBackground &= c;
          allGpuBackground &= g;
        }
      if ((allCpuBackground && !isBackground(gpu, x, y)) || (allGpuBackground && !isBackground(cpu, x, y)))
        ++a.backgroundMismatches;
      const std::size_t i = std::size_t(y) * cpu.width + x;
      const std::uint32_t gt = gpuTriangles[i], ct = cpuTriangles[i];
      if ((gt == 0) != (ct == 0) && !anyBackground) ++a.surfaceMismatches;
      if (isBackground(cpu, x, y)) continue;
      ++a.objectPixels;
      const glm::dvec3 c(cpu.at(x, y)), g(gpu.at(x, y));
      double relative = 0.0;
      for (int ch = 0; ch < 3; ++ch) relative += std::abs(g[ch] - c[ch]) / std::max(std::abs(c[ch]), darkFloor) / 3.0;
      sumRelative += relative;
      if (anyBackground) {
        ++a.silhouette;
        continue;
      }
      if (gt != ct) {
        ++a.edge;
        continue;
      }
      ++a.interior;
      for (int ch = 0; ch < 3; ++ch) {
        const double r = std::abs(g[ch] - c[ch]) / std::max(std::abs(c[ch]), darkFloor);
        if (r > a.worstInterior) a.worstInterior = r, a.worstX = x, a.worstY = y;
      }
    }
  a.meanRelative = a.objectPixels > 0 ? sumRelative / double(a.objectPixels) : 0.0;
  return a;
}

}  // namespace sslpv::test

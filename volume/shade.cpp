// Shading: the camera sees the surface; radiance comes from the LPV just inside it.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "volume/exit_law.h"
#include "volume/fresnel.h"
#include "volume/image_io.h"
#include "volume/lpv_stages.h"
#include "volume/ray_scene.h"
#include "volume/scene.h"
#include "volume/sh.h"
#include "volume/shading_surface.h"
#include "volume/single_scattering.h"

namespace sslpv {
namespace {

/// cos θo at a surface pixel: between the outward normal and the way back to the camera.
double cosOutAt(const ShadingSurface::Pixel& pixel) {
  return -glm::dot(glm::dvec3(pixel.view), glm::dvec3(pixel.normal));
}

bool entersMedium(double cosOut, double ior) { return (1.0 - cosOut * cosOut) / (ior * ior) < 1.0; }

}  // namespace

ShadingSurface traceShadingSurface(const Camera& camera, const RayScene& rays, const MaterialGrid& material, double ior) {
  ShadingSurface surface;
  surface.width = camera.width;
  surface.height = camera.height;
  const glm::dvec3 forward = glm::normalize(camera.target - camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalfY = std::tan(glm::radians(0.5 * camera.fovYDeg));
  const double tanHalfX = tanHalfY * camera.width / camera.height;
  const double cellSize = material.frame.cellSize;
  std::vector<std::vector<ShadingSurface::Pixel>> rowsFound(std::size_t(camera.height));
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<glm::vec3> origins(camera.width), dirs(camera.width);
    std::vector<RayHit> hits(camera.width);
    // A row's pixels gather here first, so that each row's list is allocated once, exactly.
    std::vector<ShadingSurface::Pixel> row;
    row.reserve(std::size_t(camera.width));
    for (int y = rows.begin(); y < rows.end(); ++y) {
      row.clear();
      for (int x = 0; x < camera.width; ++x) {
        const double u = (2.0 * (x + 0.5) / camera.width - 1.0) * tanHalfX;
        const double v = (1.0 - 2.0 * (y + 0.5) / camera.height) * tanHalfY;
        origins[x] = glm::vec3(camera.position);
        dirs[x] = glm::vec3(glm::normalize(forward + u * right + v * up));
      }
      rays.intersectMany(origins.data(), dirs.data(), hits.data(), std::size_t(camera.width));
      for (int x = 0; x < camera.width; ++x) {
        const RayHit& hit = hits[x];
        if (!hit.hit) continue;
        ShadingSurface::Pixel pixel;
        pixel.index = std::uint32_t(y) * std::uint32_t(camera.width) + std::uint32_t(x);
        pixel.position = hit.position;
        pixel.normal = hit.normal;
        pixel.view = dirs[x];
        const double cosOut = cosOutAt(pixel);
        if (cosOut <= 0.0) continue;
        const glm::dvec3 n(hit.normal), p(hit.position);
        std::size_t cells[8];
        int used = activeTrilinearWeights(material, p - 0.5 * cellSize * n, cells, pixel.weights.data());
        if (used == 0) used = activeTrilinearWeights(material, p - cellSize * n, cells, pixel.weights.data());
        if (used == 0) continue;
        pixel.used = used;
        for (int i = 0; i < used; ++i) pixel.cells[i] = std::uint32_t(cells[i]);
        pixel.refracts = entersMedium(cosOut, ior);
        if (pixel.refracts)
          pixel.single = singleScatteringGeometry(material, p, -n, refractInto(glm::dvec3(dirs[x]), n, ior));
        row.push_back(pixel);
      }
      rowsFound[std::size_t(y)].assign(row.begin(), row.end());
    }
  });
  std::size_t count = 0;
  for (const auto& row : rowsFound) count += row.size();
  surface.pixels.reserve(count);
  for (auto& row : rowsFound) surface.pixels.insert(surface.pixels.end(), row.begin(), row.end());
  return surface;
}

Image shadeSurface(const ShadingSurface& surface, const MaterialGrid& material, const ShGrid& accumulated, double ior,
                   const std::array<std::vector<float>, 3>* exitGain,
                   const std::array<std::vector<float>, 3>* reducedAlbedo,
                   const std::vector<EntryMap>* singleScattering) {
  // The calibrated exit law weights each cell by its medium's exit shape (exit_law.h).
  const bool exitLaw = reducedAlbedo != nullptr && !(*reducedAlbedo)[0].empty();
  const ExitLawTable* law = exitLaw ? &exitLawTable(ior) : nullptr;
  // Each cell's table row once per frame, not once per pixel that reads it (8 cells x 3
  // channels a pixel): the square root dominated the shading time.
  std::array<std::vector<float>, 3> lawRow;
  if (law)
    for (int ch = 0; ch < 3; ++ch) {
      const std::vector<float>& albedo = (*reducedAlbedo)[ch];
      lawRow[ch].resize(albedo.size());
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, albedo.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) lawRow[ch][i] = exitLawRow(albedo[i]);
      });
    }
  Image image(surface.width, surface.height);
  const double cellSize = material.frame.cellSize;
  // Intensity leaving a cell through its face of area A, spread as a Lambertian
  // exitance: L = (1/(Aπ)) ∫_H I(ω) dω (the seed's rendering equation).
  const double radianceScale = 1.0 / (cellSize * cellSize * SSLPV_PI);
  // Radiance divided by n² is invariant across a boundary; leaving the medium it drops by 1/η².
  const double boundaryScale = 1.0 / (ior * ior);
  const bool single = singleScattering != nullptr && !singleScattering->empty();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, surface.pixels.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) {
      const ShadingSurface::Pixel& pixel = surface.pixels[k];
      const glm::dvec3 n(pixel.normal);
      const double cosOut = cosOutAt(pixel);
      const double transmittance = 1.0 - fresnelReflectance(cosOut, ior);
      const ExitLawColumn column = exitLawColumn(float(cosOut));
      glm::vec3 radiance(0.0f);
      if (single && pixel.refracts) {
        const glm::dvec3 view(pixel.view);
        radiance = singleScatteredRadiance(material, *singleScattering, glm::dvec3(pixel.position), -n,
                                           refractInto(view, n, ior), pixel.single) *
                   float(boundaryScale * transmittance);
      }
      for (int ch = 0; ch < 3; ++ch) {
        sh::Coeffs c(0.0f);
        for (int i = 0; i < pixel.used; ++i) {
          const std::size_t cell = pixel.cells[i];
          float scale = pixel.weights[i] * (exitGain ? (*exitGain)[ch][cell] : 1.0f);
          if (law) scale *= exitLawShapeAt(*law, lawRow[ch][cell], column);
          c += scale * sh::Coeffs(accumulated.plane(ch, 0)[cell], accumulated.plane(ch, 1)[cell],
                                  accumulated.plane(ch, 2)[cell], accumulated.plane(ch, 3)[cell]);
        }
        const double exitant = std::max(0.0f, sh::hemisphereIntegral(c, glm::vec3(n)));
        radiance[ch] += float(exitant * radianceScale * boundaryScale * transmittance);
      }
      image.pixels[pixel.index] = radiance;
    }
  });
  return image;
}

Image shadeImage(const Camera& camera, const RayScene& rays, const MaterialGrid& material, const ShGrid& accumulated,
                 double ior, const std::array<std::vector<float>, 3>* exitGain,
                 const std::array<std::vector<float>, 3>* reducedAlbedo, const std::vector<EntryMap>* singleScattering) {
  return shadeSurface(traceShadingSurface(camera, rays, material, ior), material, accumulated, ior, exitGain,
                      reducedAlbedo, singleScattering);
}

}  // namespace sslpv

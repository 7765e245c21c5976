// Shading: the camera sees the surface; radiance comes from the LPV just inside it.
#include "volume/cpu/shade.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "volume/calibration/exit_law.h"
#include "volume/core/fresnel.h"
#include "volume/core/image_io.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/ray_scene.h"
#include "volume/scene/scene.h"
#include "volume/lpv/sh.h"
#include "volume/cpu/shading_surface.h"
#include "volume/cpu/single_scattering.h"
#include "volume/scene/camera_rays.h"
#include "volume/cpu/inject.h"

namespace sslpv {
namespace {

using Pixel = ShadingSurface::Pixel;

/// cos θo at a surface pixel: between the outward normal and the way back to the camera.
double cosOutAt(const Pixel& pixel) { return -glm::dot(glm::dvec3(pixel.view), glm::dvec3(pixel.normal)); }

bool entersMedium(double cosOut, double ior) { return (1.0 - cosOut * cosOut) / (ior * ior) < 1.0; }

/// Casts one image row's camera rays and finds what the shading reads at each pixel that
/// sees a lit cell. The buffers are the caller's, reused row after row.
class RowTracer {
 public:
  RowTracer(const Camera& camera, const RayScene& rays, const MaterialGrid& material, double ior)
      : camera_(camera), pixelRays_(camera), rays_(rays), material_(material), ior_(ior) {}

  struct Buffers {
    std::vector<glm::vec3> origins, dirs;
    std::vector<RayHit> hits;
  };

  void trace(int y, Buffers& b, std::vector<Pixel>& row) const {
    const int width = camera_.width;
    b.origins.resize(std::size_t(width));
    b.dirs.resize(std::size_t(width));
    b.hits.resize(std::size_t(width));
    row.clear();
    for (int x = 0; x < width; ++x) {
      b.origins[x] = glm::vec3(camera_.position);
      b.dirs[x] = glm::vec3(pixelRays_.pixelDirection(x, y));
    }
    rays_.intersectMany(b.origins.data(), b.dirs.data(), b.hits.data(), std::size_t(width));
    const double cellSize = material_.frame.cellSize;
    for (int x = 0; x < width; ++x) {
      const RayHit& hit = b.hits[x];
      if (!hit.hit) continue;
      Pixel pixel;
      pixel.index = std::uint32_t(y) * std::uint32_t(width) + std::uint32_t(x);
      pixel.position = hit.position;
      pixel.normal = hit.normal;
      pixel.view = b.dirs[x];
      const double cosOut = cosOutAt(pixel);
      if (cosOut <= 0.0) continue;
      const glm::dvec3 n(hit.normal), p(hit.position);
      std::size_t cells[8];
      int used = activeTrilinearWeights(material_, p - 0.5 * cellSize * n, cells, pixel.weights.data());
      if (used == 0) used = activeTrilinearWeights(material_, p - cellSize * n, cells, pixel.weights.data());
      if (used == 0) continue;
      pixel.used = used;
      for (int i = 0; i < used; ++i) pixel.cells[i] = std::uint32_t(cells[i]);
      pixel.refracts = entersMedium(cosOut, ior_);
      if (pixel.refracts)
        pixel.single = singleScatteringGeometry(material_, p, -n, refractInto(glm::dvec3(b.dirs[x]), n, ior_));
      row.push_back(pixel);
    }
  }

 private:
  const Camera& camera_;
  const CameraRays pixelRays_;
  const RayScene& rays_;
  const MaterialGrid& material_;
  double ior_;
};

/// The radiance of traced pixels from one frame's lattice and lights.
class PixelShader {
 public:
  PixelShader(const MaterialGrid& material, const ShGrid& accumulated, double ior,
              const std::array<std::vector<float>, 3>* exitGain, const std::array<std::vector<float>, 3>* reducedAlbedo,
              const std::vector<EntryMap>* singleScattering)
      : material_(material), accumulated_(accumulated), ior_(ior), exitGain_(exitGain),
        singleScattering_(singleScattering != nullptr && !singleScattering->empty() ? singleScattering : nullptr) {
    // The calibrated exit law weights each cell by its medium's exit shape (exit_law.h).
    if (reducedAlbedo != nullptr && !(*reducedAlbedo)[0].empty()) {
      law_ = &exitLawTable(ior);
      // Each cell's table row once per frame, not once per pixel that reads it (8 cells x
      // 3 channels a pixel): the square root dominated the shading time.
      for (int ch = 0; ch < 3; ++ch) {
        const std::vector<float>& albedo = (*reducedAlbedo)[ch];
        lawRow_[ch].resize(albedo.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, albedo.size()), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i < r.end(); ++i) lawRow_[ch][i] = exitLawRow(albedo[i]);
        });
      }
    }
    const double cellSize = material.frame.cellSize;
    // Intensity leaving a cell through its face of area A, spread as a Lambertian
    // exitance: L = (1/(Aπ)) ∫_H I(ω) dω (the seed's rendering equation).
    radianceScale_ = 1.0 / (cellSize * cellSize * SSLPV_PI);
    // Radiance divided by n² is invariant across a boundary; leaving the medium it drops by 1/η².
    boundaryScale_ = 1.0 / (ior * ior);
  }

  void shade(const std::vector<Pixel>& row, Image& image) const {
    for (const Pixel& pixel : row) image.pixels[pixel.index] = radiance(pixel);
  }

 private:
  glm::vec3 radiance(const Pixel& pixel) const {
    const glm::dvec3 n(pixel.normal);
    const double cosOut = cosOutAt(pixel);
    const double transmittance = 1.0 - fresnelReflectance(cosOut, ior_);
    const ExitLawColumn column = exitLawColumn(float(cosOut));
    glm::vec3 radiance(0.0f);
    if (singleScattering_ && pixel.refracts)
      radiance = singleScatteredRadiance(material_, *singleScattering_, glm::dvec3(pixel.position), -n,
                                         refractInto(glm::dvec3(pixel.view), n, ior_), pixel.single) *
                 float(boundaryScale_ * transmittance);
    for (int ch = 0; ch < 3; ++ch) {
      sh::Coeffs c(0.0f);
      for (int i = 0; i < pixel.used; ++i) {
        const std::size_t cell = pixel.cells[i];
        float scale = pixel.weights[i] * (exitGain_ ? (*exitGain_)[ch][cell] : 1.0f);
        if (law_) scale *= exitLawShapeAt(*law_, lawRow_[ch][cell], column);
        c += scale * sh::Coeffs(accumulated_.plane(ch, 0)[cell], accumulated_.plane(ch, 1)[cell],
                                accumulated_.plane(ch, 2)[cell], accumulated_.plane(ch, 3)[cell]);
      }
      const double exitant = std::max(0.0f, sh::hemisphereIntegral(c, glm::vec3(n)));
      radiance[ch] += float(exitant * radianceScale_ * boundaryScale_ * transmittance);
    }
    return radiance;
  }

  const MaterialGrid& material_;
  const ShGrid& accumulated_;
  double ior_;
  const std::array<std::vector<float>, 3>* exitGain_;
  const std::vector<EntryMap>* singleScattering_;
  const ExitLawTable* law_ = nullptr;
  std::array<std::vector<float>, 3> lawRow_;
  double radianceScale_ = 0.0, boundaryScale_ = 0.0;
};

/// Traces every image row in parallel and hands each row's pixels to `use(y, row)`; the
/// row buffer is reused, so `use` copies what it keeps.
template <typename UseRow>
void forEachTracedRow(const Camera& camera, const RowTracer& tracer, UseRow&& use) {
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    RowTracer::Buffers buffers;
    std::vector<Pixel> row;
    row.reserve(std::size_t(camera.width));
    for (int y = rows.begin(); y < rows.end(); ++y) {
      tracer.trace(y, buffers, row);
      use(y, row);
    }
  });
}

}  // namespace

ShadingSurface traceShadingSurface(const Camera& camera, const RayScene& rays, const MaterialGrid& material, double ior) {
  ShadingSurface surface;
  surface.width = camera.width;
  surface.height = camera.height;
  surface.rows.resize(std::size_t(camera.height));
  // A row's pixels gather in a reused buffer first, so each kept row is allocated once, exactly.
  forEachTracedRow(camera, RowTracer(camera, rays, material, ior),
                   [&](int y, const std::vector<Pixel>& row) { surface.rows[std::size_t(y)].assign(row.begin(), row.end()); });
  return surface;
}

Image shadeSurface(const ShadingSurface& surface, const MaterialGrid& material, const ShGrid& accumulated, double ior,
                   const std::array<std::vector<float>, 3>* exitGain,
                   const std::array<std::vector<float>, 3>* reducedAlbedo,
                   const std::vector<EntryMap>* singleScattering) {
  Image image(surface.width, surface.height);
  const PixelShader shader(material, accumulated, ior, exitGain, reducedAlbedo, singleScattering);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, surface.rows.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t y = r.begin(); y < r.end(); ++y) shader.shade(surface.rows[y], image);
  });
  return image;
}

Image shadeImage(const Camera& camera, const RayScene& rays, const MaterialGrid& material, const ShGrid& accumulated,
                 double ior, const std::array<std::vector<float>, 3>* exitGain,
                 const std::array<std::vector<float>, 3>* reducedAlbedo, const std::vector<EntryMap>* singleScattering) {
  // Row by row, keeping nothing: a frame whose view is not reused should not pay for
  // storing it (tens of MB of fresh pages at 512²).
  Image image(camera.width, camera.height);
  const PixelShader shader(material, accumulated, ior, exitGain, reducedAlbedo, singleScattering);
  forEachTracedRow(camera, RowTracer(camera, rays, material, ior),
                   [&](int, const std::vector<Pixel>& row) { shader.shade(row, image); });
  return image;
}

}  // namespace sslpv

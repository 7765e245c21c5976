#pragma once
// The camera's view of the object as the CPU shading reads it, split from the shading
// itself: which pixels see the object, where, and which cells each reads. Only the camera,
// the mesh and the grid decide it; a light move or a stroke changes everything else, so a
// renderer keeps it between such frames instead of casting the camera rays again.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "volume/core/image_io.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/cpu/single_scattering.h"

namespace sslpv {

class RayScene;
struct Camera;

struct ShadingSurface {
  int width = 0, height = 0;
  struct Pixel {
    std::uint32_t index = 0;  ///< y · width + x
    glm::vec3 position{0.0f}, normal{0.0f};
    glm::vec3 view{0.0f};     ///< unit camera ray direction
    bool refracts = false;    ///< the view ray enters the medium (no total internal reflection)
    int used = 0;             ///< lattice cells read (activeTrilinearWeights half a cell, else a cell, inside)
    std::array<std::uint32_t, 8> cells{};
    std::array<float, 8> weights{};
    SingleScatteringGeometry single;  ///< filled where `refracts`
  };
  /// Per image row, the pixels that see a lit cell, left to right.
  std::vector<std::vector<Pixel>> rows;
};

/// Casts the camera's rays and finds, per pixel, what shadeSurface reads.
ShadingSurface traceShadingSurface(const Camera& camera, const RayScene& rays, const MaterialGrid& material, double ior);

/// shadeImage (lpv_stages.h) on a traced surface: the same image, bit for bit. shadeImage
/// itself traces and shades row by row without keeping the surface, for frames whose view
/// is not reused.
Image shadeSurface(const ShadingSurface& surface, const MaterialGrid& material, const ShGrid& accumulated, double ior,
                   const std::array<std::vector<float>, 3>* exitGain = nullptr,
                   const std::array<std::vector<float>, 3>* reducedAlbedo = nullptr,
                   const std::vector<EntryMap>* singleScattering = nullptr);

}  // namespace sslpv

// Light that crosses an object, SSLPV against exact transport (docs/design.md §6.7.9). A slab 60 x 60 mm
// wide and L thick, lit from above by a directional light along its normal and seen from
// below along its normal: the radiance of its unlit face's middle, where the light comes
// out only after crossing the slab. Ground truth is adding-doubling for the same slab
// (volume/calibration/adding_doubling.h: exact transport for the laterally infinite slab with the
// material's reduced albedo and a smooth boundary on both faces), so there is no noise to
// average: the ratio is SSLPV's own error, up to the slab's finite width.
//
//   slab_transmission [--grid 100] [--thickness 4,10,20] [--materials jade,ketchup,skin1,marble]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/image_mean.h"
#include "bench/slab_scene.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace {

using namespace sslpv;

/// The shipped jade_slab_backlit medium beside Jensen's measured ones (g = 0 there, so
/// σs' = σs).
MeasuredMaterial jade() {
  return MeasuredMaterial{"jade", glm::vec3(0.8f, 1.0f, 0.7f), glm::vec3(0.2f, 0.025f, 0.15f), 1.5f};
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Flags flags(argc, argv, {"grid", "thickness", "materials"},
                           "slab_transmission [--grid N] [--thickness a,b] [--materials a,b]");
  if (!flags.ok()) return 2;
  const int grid = flags.integer("grid", 100);
  std::vector<double> thicknesses;
  for (const std::string& t : flags.names("thickness", {"4", "10", "20"})) thicknesses.push_back(std::atof(t.c_str()));
  if (grid < 8 || thicknesses.empty() ||
      std::any_of(thicknesses.begin(), thicknesses.end(), [](double t) { return !(t > 0.0 && t < 100.0); })) {
    std::fprintf(stderr, "slab_transmission: need --grid >= 8 and thicknesses in (0, 100) mm\n");
    return 2;
  }
  std::vector<MeasuredMaterial> materials = {jade()};
  materials.insert(materials.end(), measuredMaterials().begin(), measuredMaterials().end());
  bool known = true;
  const std::vector<MeasuredMaterial> picked = bench::pickMaterials(
      materials, flags.names("materials", {"jade", "ketchup", "skin1", "marble"}), "slab_transmission", known);
  if (!known) return 2;
  std::printf("# slab 60x60 mm, L thick, lit from above along its normal, seen from below; SSLPV calibrated,\n");
  std::printf("# grid %d (cell %.2f mm), steps auto, against adding-doubling (exact). SSLPV / exact of the\n", grid,
              2.0 * bench::kBacklitHalfWidth / grid);
  std::printf("# transmitted radiance along the normal; 'exact' is its pi L / E, red.\n");
  std::printf("%-9s %6s %7s %7s %7s %10s\n", "material", "L mm", "R", "G", "B", "exact R");
  for (const MeasuredMaterial& material : picked) {
    for (double thickness : thicknesses) {
      const Scene scene = bench::backlitSlab(material, thickness);
      const glm::dvec3 lpv = bench::meanRadiance(CpuRenderer(scene).render(bench::calibratedAuto(grid))) * M_PI;
      glm::dvec3 exact(0.0);
      for (int ch = 0; ch < 3; ++ch) exact[ch] = bench::exactNormalTransmission(material, ch, thickness);
      const glm::dvec3 ratio = lpv / exact;
      std::printf("%-9s %6.1f %7.3f %7.3f %7.3f %10.3e\n", std::string(material.name).c_str(), thickness, ratio.x,
                  ratio.y, ratio.z, exact.x);
      std::fflush(stdout);
    }
  }
  return 0;
}

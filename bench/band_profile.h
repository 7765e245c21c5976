#pragma once
// SSLPV against the path tracer band by band over an image (rings round a lit disk,
// depths below a lit edge): the shared sums and table rows of lateral_spread and
// edge_crossing.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/vec3.hpp>
#include <string_view>
#include <vector>

#include "bench/slab_scene.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/core/image_io.h"
#include "volume/reference/reference_tracer.h"

namespace sslpv::bench {

struct BandSums {
  glm::dvec3 lpv{0.0}, reference{0.0}, variance{0.0};
  int pixels = 0;
};

/// Index of the band [edges[k], edges[k + 1]) holding `value`, -1 outside them all.
inline int bandOf(const std::vector<double>& edges, double value) {
  const int k = int(std::upper_bound(edges.begin(), edges.end(), value) - edges.begin()) - 1;
  return k < int(edges.size()) - 1 ? k : -1;
}

/// Sums both images over the bands; bandAt(x, y) is a pixel's band (-1: none).
template <class BandAt>
std::vector<BandSums> bandSums(const Image& lpv, const ReferenceResult& truth, int bandCount, BandAt&& bandAt) {
  std::vector<BandSums> bands(static_cast<std::size_t>(bandCount));
  for (int y = 0; y < lpv.height; ++y)
    for (int x = 0; x < lpv.width; ++x) {
      const int band = bandAt(x, y);
      if (band < 0 || band >= bandCount) continue;
      BandSums& s = bands[std::size_t(band)];
      const glm::dvec3 se(truth.standardError.at(x, y));
      s.lpv += glm::dvec3(lpv.at(x, y));
      s.reference += glm::dvec3(truth.radiance.at(x, y));
      s.variance += se * se;
      ++s.pixels;
    }
  return bands;
}

/// Prints one row per band: SSLPV / path tracer per channel ("-" where the path tracer's
/// band mean is below `negligible` of the first band's: a channel that has died out there
/// says nothing), the path tracer's red band mean over the first band's, and the largest
/// relative standard error of the compared channels.
inline void printBands(std::string_view material, const std::vector<double>& edges,
                       const std::vector<BandSums>& bands, double negligible) {
  const glm::dvec3 first = bands[0].reference / double(std::max(1, bands[0].pixels));
  for (std::size_t k = 0; k < bands.size(); ++k) {
    const BandSums& s = bands[k];
    if (s.pixels == 0) continue;
    const glm::dvec3 mean = s.reference / double(s.pixels);
    char band[32], cells[3][16];
    std::snprintf(band, sizeof band, "%g-%g", edges[k], edges[k + 1]);
    double worstSe = 0.0;
    for (int ch = 0; ch < 3; ++ch) {
      if (!(mean[ch] > negligible * first[ch])) {
        std::snprintf(cells[ch], sizeof cells[ch], "%7s", "-");
        continue;
      }
      std::snprintf(cells[ch], sizeof cells[ch], "%7.3f", s.lpv[ch] / s.reference[ch]);
      worstSe = std::max(worstSe, std::sqrt(s.variance[ch]) / s.reference[ch]);
    }
    char se[16];
    if (worstSe > 0.0)
      std::snprintf(se, sizeof se, "%7.1f%%", 100.0 * worstSe);
    else
      std::snprintf(se, sizeof se, "%8s", "-");
    std::printf("%-9.*s %-9s %s %s %s %10.2e %s\n", int(material.size()), material.data(), band, cells[0], cells[1],
                cells[2], mean.x / first.x, se);
  }
  std::fflush(stdout);
}

/// The flags both band benchmarks take: --grid (SSLPV's), --spp and --size (the path
/// tracer's samples and image size), --materials (default ketchup, skin1, marble).
struct BandRun {
  int grid = 100, spp = 64, size = 128;
  std::vector<MeasuredMaterial> materials;
};

/// Parses the flags; false (after printing why) on anything it cannot use.
inline bool parseBandRun(int argc, char** argv, const char* program, BandRun& run) {
  const std::string usage = std::string(program) + " [--grid N] [--spp N] [--size N] [--materials a,b]";
  const Flags flags(argc, argv, {"grid", "spp", "size", "materials"}, usage.c_str());
  if (!flags.ok()) return false;
  bool known = true;
  run.materials =
      pickMaterials(measuredMaterials(), flags.names("materials", {"ketchup", "skin1", "marble"}), program, known);
  if (!known) return false;
  run.grid = flags.integer("grid", run.grid);
  run.spp = flags.integer("spp", run.spp);
  run.size = flags.integer("size", run.size);
  if (run.grid < 8 || run.spp < 1 || run.size < 16) {
    std::fprintf(stderr, "%s: need --grid >= 8, --spp >= 1, --size >= 16\n", program);
    return false;
  }
  return true;
}

/// Renders `scene` with the path tracer and calibrated SSLPV and prints their bands.
template <class BandAt>
void compareBands(const Scene& scene, std::string_view material, const BandRun& run,
                  const std::vector<double>& edges, double negligible, BandAt&& bandAt) {
  ReferenceOptions options;
  options.spp = run.spp;
  const ReferenceResult truth = ReferenceTracer(scene).render(options);
  const Image lpv = CpuRenderer(scene).render(calibratedAuto(run.grid));
  printBands(material, edges, bandSums(lpv, truth, int(edges.size()) - 1, bandAt), negligible);
}

}  // namespace sslpv::bench

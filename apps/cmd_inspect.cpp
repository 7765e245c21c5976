#include "apps/cmd_inspect.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>

#include "volume/material/material_set.h"

namespace sslpv {
namespace {

/// Per-channel minimum and maximum of the values fed to add().
struct RgbRange {
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  std::size_t count = 0;
  void add(const double (&v)[3]) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], v[c]);
      hi[c] = std::max(hi[c], v[c]);
    }
    ++count;
  }
};

std::string rangeText(double lo, double hi) {
  char text[80];
  std::snprintf(text, sizeof text, "%.4g .. %.4g", lo, hi);
  return text;
}

void printRgb(std::ostream& out, const std::string& label, const RgbRange& range, const std::string& what) {
  out << "  " << label << " (" << range.count << " " << what << "):";
  if (range.count == 0) {
    out << " none\n";
    return;
  }
  const char* channel[] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) out << (c ? ", " : " ") << channel[c] << " " << rangeText(range.lo[c], range.hi[c]);
  out << "\n";
}

}  // namespace

void printMaterialSummary(const std::filesystem::path& file, std::ostream& out) {
  const std::shared_ptr<const MaterialSet> set = loadMaterialSet(file);
  RgbRange albedo, meanFreePath;
  auto sigmaS = set->sigmaS->getConstAccessor();
  const bool sameTransform = set->sigmaT->constTransform() == set->sigmaS->constTransform();
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3s t = *it;
    // A zero σt is a voxel light crosses without interacting: an infinite free path.
    const double mfp[3] = {t[0] > 0 ? 1.0 / t[0] : std::numeric_limits<double>::infinity(),
                           t[1] > 0 ? 1.0 / t[1] : std::numeric_limits<double>::infinity(),
                           t[2] > 0 ? 1.0 / t[2] : std::numeric_limits<double>::infinity()};
    meanFreePath.add(mfp);
    // Where σs is inactive the renderers use the scene's base σs, which the file does not know.
    openvdb::Vec3s s;
    if (!sameTransform || !sigmaS.probeValue(it.getCoord(), s)) continue;
    const double a[3] = {t[0] > 0 ? s[0] / t[0] : 0.0, t[1] > 0 ? s[1] / t[1] : 0.0, t[2] > 0 ? s[2] / t[2] : 0.0};
    albedo.add(a);
  }
  out << "summary (over active voxels and tiles; lengths in " << set->units << "):\n";
  printRgb(out, "albedo sigma_s/sigma_t", albedo, "active in both grids");
  printRgb(out, "mean free path 1/sigma_t", meanFreePath, "active");
  if (!set->g) {
    out << "  g: no grid (the scene's base g everywhere)\n";
    return;
  }
  double gLo = std::numeric_limits<double>::infinity(), gHi = -gLo;
  std::size_t gCount = 0;
  for (auto it = set->g->cbeginValueOn(); it; ++it) {
    gLo = std::min(gLo, double(*it));
    gHi = std::max(gHi, double(*it));
    ++gCount;
  }
  out << "  g (" << gCount << " active): " << (gCount ? rangeText(gLo, gHi) : std::string("none")) << "\n";
}

}  // namespace sslpv

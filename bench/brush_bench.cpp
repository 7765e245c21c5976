// Cost of brush strokes (editor/brush_engine.h): a straight 100-dab stroke (spacing
// radius/4) of radius 8 voxels through a 256-unit object painted at 1 unit per voxel (a
// 256³-equivalent extent), per mode, plus undo and redo of it. Prints the median of
// --runs fresh runs, as thread CPU time (robust on a shared machine) and wall time.
// Usage: brush_bench [--runs N] [--radius VOXELS] [--dabs N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "editor/brush_engine.h"

namespace {

using namespace sslpv;
using Clock = std::chrono::steady_clock;

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Case {
  const char* name;
  std::function<Brush(double radius)> brush;
};

}  // namespace

int main(int argc, char** argv) {
  int runs = 7, dabs = 100;
  double radius = 8.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--runs"))
      runs = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--radius"))
      radius = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--dabs"))
      dabs = std::max(2, std::atoi(argv[i + 1]));
    else {
      std::fprintf(stderr, "usage: brush_bench [--runs N] [--radius VOXELS] [--dabs N]\n");
      return 2;
    }
  }
  const MaterialSample base{{1.0f, 1.2f, 1.4f}, {0.9f, 1.0f, 1.1f}, 0.0f};
  auto brush = [](BrushChannel c, BrushMode m, double r) {
    Brush b;
    b.channel = c;
    b.mode = m;
    b.radius = r;
    b.strength = 0.5;
    b.rgb = glm::dvec3(4.0, 5.0, 6.0);
    b.scalar = 0.3;
    return b;
  };
  const std::vector<Case> cases = {
      {"set sigma_t (empty grid)", [&](double r) { return brush(BrushChannel::SigmaT, BrushMode::Set, r); }},
      {"set sigma_t (painted)", [&](double r) { return brush(BrushChannel::SigmaT, BrushMode::Set, r); }},
      {"add g", [&](double r) { return brush(BrushChannel::G, BrushMode::Add, r); }},
      {"preset marble",
       [&](double r) {
         Brush b = brush(BrushChannel::Preset, BrushMode::Set, r);
         b.preset = "marble";
         return b;
       }},
      {"smooth all", [&](double r) { return brush(BrushChannel::All, BrushMode::Smooth, r); }},
      {"erase all", [&](double r) { return brush(BrushChannel::All, BrushMode::Erase, r); }},
      {"set sigma_t + mirror x",
       [&](double r) {
         Brush b = brush(BrushChannel::SigmaT, BrushMode::Set, r);
         b.mirror = BrushMirror{0, std::nullopt};
         return b;
       }},
  };
  // A segment whose dab count is exactly `dabs`: length (dabs - 1) spacings of radius/4.
  const double length = (dabs - 1) * radius / 4.0;
  const glm::dvec3 from(-length / 2, 3.3, -1.7), to(length / 2, 3.3, -1.7);

  std::printf(
      "brush stroke cost: %d dabs, radius %.3g voxels, falloff smooth, 1 unit per voxel, object 256 units, "
      "median of %d runs\n",
      dabs, radius, runs);
  std::printf("%-26s %10s %10s %10s %10s %12s %10s %10s\n", "case", "cpu ms", "wall ms", "us/dab", "voxels", "Mvoxel/s",
              "undo ms", "redo ms");
  for (const Case& c : cases) {
    std::vector<double> stroke, wall, undo, redo;
    std::size_t changed = 0;
    for (int run = 0; run < runs; ++run) {
      PaintTarget target;
      target.set = makeEmptyMaterialSet(base, 1.0, "mm");
      target.base = base;
      target.restBounds.extend(glm::dvec3(-128.0));
      target.restBounds.extend(glm::dvec3(128.0));
      BrushEngine engine(target);
      if (std::string(c.name).find("empty") == std::string::npos) {
        // Something to smooth, erase or repaint: a wider stroke first (not timed).
        Brush under = brush(BrushChannel::AlbedoMfp, BrushMode::Set, radius * 1.5);
        under.albedo = glm::dvec3(0.8, 0.5, 0.3);
        under.meanFreePath = glm::dvec3(0.5);
        engine.applyStroke({under, {from, to}, {}});
      }
      const Stroke s{c.brush(radius), {from, to}, {}};
      const auto t0 = Clock::now();
      const double c0 = threadCpuMs();
      const StrokeResult result = engine.applyStroke(s);
      const double c1 = threadCpuMs();
      const auto t1 = Clock::now();
      engine.undo();
      const double c2 = threadCpuMs();
      engine.redo();
      const double c3 = threadCpuMs();
      if (int(result.dabs) != dabs) std::fprintf(stderr, "warning: %zu dabs, expected %d\n", result.dabs, dabs);
      stroke.push_back(c1 - c0);
      wall.push_back(ms(t0, t1));
      undo.push_back(c2 - c1);
      redo.push_back(c3 - c2);
      changed = result.voxelsChanged;
    }
    const double strokeMs = median(stroke);
    // Voxel visits: every voxel centre inside each dab's sphere (and its mirror).
    const double visits = dabs * (4.0 / 3.0) * 3.14159265358979 * radius * radius * radius *
                          (std::string(c.name).find("mirror") != std::string::npos ? 2.0 : 1.0);
    std::printf("%-26s %10.2f %10.2f %10.1f %10zu %12.1f %10.2f %10.2f\n", c.name, strokeMs, median(wall),
                1000.0 * strokeMs / dabs, changed, visits / (strokeMs * 1000.0), median(undo), median(redo));
  }
  return 0;
}

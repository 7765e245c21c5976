// LPV propagation per step, Vulkan backend (device-resident: GpuPropagator::runOnDevice)
// against the CPU backend (sslpv::propagate), on cubic grids filled as a full cube, a
// sphere or a thin spherical shell. Prints a table; a program, not a test (no asserts).
//
//   gpu_propagation_bench [--sizes 16,32,64,128] [--steps 4,8,16,32,auto]
//                         [--shapes cube,sphere,shell] [--schemes seed,calibrated]
//                         [--repeats 5] [--rows N] [--zchunk N] [--no-cpu]
//
// Every time is the MEDIAN of --repeats runs after one warm-up run (shader JIT, caches).
// GPU ms/step: propagation kernel + per-step reduction from GPU timestamps, divided by
// the steps that ran; "wall" adds submission and synchronization (runOnDevice as a whole,
// no host upload or readback). CPU ms/step: wall time of propagate(). Mcells/s counts
// ACTIVE cells x steps per second, so a sphere and a cube compare on useful work.
//
// Roofline. The same run measures the device's own peaks, again just before every row: FMA rate (lpv_peak_fma.comp)
// and copy bandwidth (the vec4 STREAM triad of lpv_peak_triad.comp, read as storage
// buffers and as texel buffers; the better of the two is the roof). Work per active cell
// and step, counted by hand from the kernel as written (shaders/lpv_transfer.glsl and
// lpv_propagate.comp), 1 flop per add, sub, mul, max or div, halo cells that are
// normalized a second time not counted (useful work only):
//   normalize the cell and form its 6 lobes: 3 channels x (169 for the 30 clamped faces
//     and their lobes + 7 for the scale and power sums + 24 scaling the lobes)  = 600
//   gather: 6 lobes of 4 floats added per channel                              =  72
//   step factors + power sums                                                  =  42
//   accumulate (2 adds x 12 floats, every other step)                           =  12
//   total                                                                        726 flop
// (the CPU's structure, normalize then evaluate the faces again per neighbour, needs
// 1024). Bytes per active cell and step, compulsory memory traffic (halos assumed
// cached): source 48 + factors 32 + destination 48 + accumulated (48 read + 48 written
// every other step) 48 = 176 B, so 4.1 flop/B. Attainable = min(peak FMA, 4.1 x
// bandwidth); "roof %" is the kernel's achieved GFLOP/s over that.
// The calibrated scheme keeps every cell isotropic, so its steps after the first run as
// a stencil on c0 ("calibrated/iso" rows; "calibrated/gen" rows force the kernel above
// on the same factors, for comparison): per channel, the cell's power and its lobe (4),
// the 6 lobes added as vec4 (24), retention (2), step factors and power sums (13),
// accumulate (4) = 141 flop on the same 176 B, so those rows are bandwidth-bound (their
// first step is general: bench::propagationFlopsPerCellStep averages the two).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/device_peaks.h"
#include "gpu/vk/compute.h"
#include "gpu/passes/gpu_propagation.h"
#include "shaders/spirv_library.h"
#include "device_shared/lpv_constants.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/cpu/propagate.h"

namespace {
using namespace sslpv;

using bench::kBytesPerCellStep;
using bench::kFlopsPerCellStep;
using bench::PeakProbe;
using bench::Peaks;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Processor time of the whole process (lavapipe's worker threads included): on a shared
/// machine it shows how much work a run was, whatever else competes for the cores.
double processCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

enum class Shape { Cube, Sphere, Shell };
const char* shapeName(Shape s) { return s == Shape::Cube ? "cube" : s == Shape::Sphere ? "sphere" : "shell"; }

/// A translucent material (albedo near 1, mild forward scattering) on an n^3 grid:
/// every interior cell (cube), a ball of radius 0.45 n (sphere, ~38 % of the cube), or
/// its outer 2 cells (shell).
MaterialGrid makeMaterial(int n, Shape shape) {
  MaterialGrid m;
  m.frame.dims = glm::ivec3(n);
  const std::size_t cells = m.frame.cellCount();
  m.coverage.assign(cells, 0.0f);
  m.sigmaT.assign(cells, glm::vec3(1.0f, 1.2f, 1.5f));
  m.sigmaS.assign(cells, glm::vec3(0.95f, 1.0f, 1.1f));
  m.g.assign(cells, 0.2f);
  const double c = 0.5 * n, radius = 0.45 * n;
  for (int z = 1; z < n - 1; ++z)
    for (int y = 1; y < n - 1; ++y)
      for (int x = 1; x < n - 1; ++x) {
        const double r = std::sqrt((x + 0.5 - c) * (x + 0.5 - c) + (y + 0.5 - c) * (y + 0.5 - c) +
                                   (z + 0.5 - c) * (z + 0.5 - c));
        const bool inside = shape == Shape::Cube || (r < radius && (shape == Shape::Sphere || r > radius - 2.0));
        if (inside) m.coverage[m.frame.index(x, y, z)] = 1.0f;
      }
  return m;
}

/// Light in every active cell (an isotropic part plus a tilt), none elsewhere, as
/// injection leaves it; no cell takes a shortcut.
ShGrid litField(const MaterialGrid& m, const StepFactors& factors) {
  ShGrid field;
  field.resize(m.frame);
  for (std::size_t i = 0; i < m.frame.cellCount(); ++i)
    if (factors.active[i])
      for (int ch = 0; ch < 3; ++ch) {
        field.plane(ch, 0)[i] = 1.0f + 0.01f * float(i % 7);
        field.plane(ch, 1)[i] = 0.3f;
        field.plane(ch, 3)[i] = -0.2f;
      }
  return field;
}


struct BenchOptions {
  std::vector<int> sizes{16, 32, 64, 128};
  std::vector<int> steps{4, 8, 16, 32, 0};  // 0: auto
  std::vector<Shape> shapes{Shape::Cube, Shape::Sphere, Shape::Shell};
  std::vector<LpvScheme> schemes{LpvScheme::Seed};
  int repeats = 5;
  bool cpu = true;
  gpu::GpuPropagatorOptions gpu;
};

/// A whole-string integer, or std::invalid_argument naming the flag.
int parseInt(const std::string& flag, const std::string& value) {
  std::size_t used = 0;
  int parsed = 0;
  try {
    parsed = std::stoi(value, &used);
  } catch (const std::logic_error&) {
    used = 0;
  }
  if (used == 0 || used != value.size()) throw std::invalid_argument("malformed value " + value + " for " + flag);
  return parsed;
}

std::vector<std::string> splitList(const std::string& value) {
  std::vector<std::string> items;
  std::stringstream in(value);
  for (std::string item; std::getline(in, item, ',');) items.push_back(item);
  return items;
}

/// std::invalid_argument names the flag or value that is wrong.
BenchOptions parseOptions(int argc, char** argv) {
  BenchOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--no-cpu") {
      options.cpu = false;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument("missing value after " + flag);
    const std::string value = argv[++i];
    if (flag == "--sizes") {
      options.sizes.clear();
      for (const std::string& item : splitList(value)) options.sizes.push_back(parseInt(flag, item));
    } else if (flag == "--steps") {
      options.steps.clear();
      for (const std::string& item : splitList(value)) options.steps.push_back(item == "auto" ? 0 : parseInt(flag, item));
    } else if (flag == "--shapes") {
      options.shapes.clear();
      for (const std::string& item : splitList(value)) {
        if (item == "cube") options.shapes.push_back(Shape::Cube);
        else if (item == "sphere") options.shapes.push_back(Shape::Sphere);
        else if (item == "shell") options.shapes.push_back(Shape::Shell);
        else throw std::invalid_argument("unknown shape " + item + " for --shapes (cube, sphere, shell)");
      }
    } else if (flag == "--schemes") {
      options.schemes.clear();
      for (const std::string& item : splitList(value)) {
        LpvScheme scheme{};
        if (!parseLpvScheme(item, scheme))
          throw std::invalid_argument("unknown scheme " + item + " for --schemes (seed, calibrated)");
        options.schemes.push_back(scheme);
      }
    } else if (flag == "--repeats") {
      options.repeats = parseInt(flag, value);
    } else if (flag == "--rows") {
      options.gpu.tileRows = parseInt(flag, value);
    } else if (flag == "--zchunk") {
      options.gpu.zChunk = parseInt(flag, value);
    } else {
      throw std::invalid_argument("unknown option " + flag);
    }
  }
  if (options.repeats < 1) throw std::invalid_argument("--repeats must be at least 1");
  return options;
}

struct GpuRun {
  int steps = 0;
  double kernelMs = 0.0, wallMs = 0.0, cpuMs = 0.0;  // per step, medians
};

GpuRun benchGpu(gpu::GpuPropagator& propagator, const ShGrid& injected, const PropagationOptions& options,
                int repeats) {
  std::vector<double> kernel, wall, cpu;
  GpuRun run;
  for (int r = 0; r <= repeats; ++r) {  // run 0 warms up (JIT, first touch of memory)
    propagator.uploadField(injected, propagator.sourceField(), true);  // stands in for GPU injection
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = processCpuSeconds();
    const PropagationResult result = propagator.runOnDevice(options);
    const double seconds = secondsSince(start), cpuSeconds = processCpuSeconds() - cpuStart;
    run.steps = std::max(result.stepsRun, 1);
    if (r == 0) continue;
    const gpu::GpuPropagationTimings& t = propagator.timings();
    kernel.push_back((t.propagateMs + t.reduceMs) / run.steps);
    wall.push_back(seconds * 1e3 / run.steps);
    cpu.push_back(cpuSeconds * 1e3 / run.steps);
  }
  run.kernelMs = median(kernel);
  run.wallMs = median(wall);
  run.cpuMs = median(cpu);
  return run;
}

double benchCpu(const MaterialGrid& material, const StepFactors& factors, const ShGrid& injected,
                const PropagationOptions& options, int repeats) {
  std::vector<double> ms;
  for (int r = 0; r <= repeats; ++r) {
    ShGrid field = injected, accumulated;
    accumulated.resize(material.frame);
    const auto start = std::chrono::steady_clock::now();
    const PropagationResult result = propagate(material, factors, field, accumulated, options);
    if (r > 0) ms.push_back(secondsSince(start) * 1e3 / std::max(result.stepsRun, 1));
  }
  return median(ms);
}

}  // namespace

int main(int argc, char** argv) {
  BenchOptions bench;
  try {
    bench = parseOptions(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gpu_propagation_bench: %s\n", e.what());
    return 2;
  }
  try {
    gpu::VulkanDevice device;
    PeakProbe probe(device);
    const double intensity = kFlopsPerCellStep / kBytesPerCellStep;  // the general step's
    const Peaks start = probe.measure(bench.repeats);
    std::printf("device: %s; times are medians of %d runs after a warm-up\n", device.name().c_str(), bench.repeats);
    std::printf("peaks at the start: FMA %.1f GFLOP/s; vec4 triad %.2f GB/s (storage buffers), %.2f GB/s (texel reads)\n",
                start.fmaGflops, start.ssboGBs, start.texelGBs);
    std::printf("per active cell-step: %.0f flop, %.0f B (%.1f flop/B); roofline = min(FMA peak, %.1f x triad peak),\n"
                "both peaks measured again just before each row (peak GF, GB/s columns)\n",
                kFlopsPerCellStep, kBytesPerCellStep, intensity, intensity);
    std::printf("%5s %6s %14s %5s %8s %8s %5s | %8s %8s %8s %8s %7s %7s | %7s %6s %6s | %8s %8s %7s\n", "grid",
                "shape", "scheme/step", "steps", "active", "covered", "items", "gpu ms", "wall ms", "proc ms", "Mcell/s", "GFLOP/s", "GB/s",
                "peak GF", "GB/s", "roof%", "cpu ms", "Mcell/s", "cpu/gpu");
    for (int n : bench.sizes)
      for (Shape shape : bench.shapes) {
        const MaterialGrid material = makeMaterial(n, shape);
        for (LpvScheme scheme : bench.schemes) {
          const StepFactors factors = computeStepFactors(material, scheme, 1.4);
          const ShGrid injected = litField(material, factors);
          // The calibrated scheme's isotropic steps, and its factors through the general step.
          const bool isotropicScheme = keepsCellsIsotropic(factors);
          for (bool isotropic : isotropicScheme ? std::vector<bool>{false, true} : std::vector<bool>{false}) {
            gpu::GpuPropagatorOptions gpuOptions = bench.gpu;
            gpuOptions.isotropicSteps = isotropic;
            gpu::GpuPropagator propagator(device, material.frame, factors, gpuOptions);
            const double active = double(propagator.activeCells());
            const std::string variant = lpvSchemeName(scheme) + (isotropicScheme ? isotropic ? "/iso" : "/gen" : "");
            for (int steps : bench.steps) {
              PropagationOptions options;
              options.steps = steps;
              options.autoSteps = steps == 0;
              options.isotropicFastPath = isotropic;
              const Peaks peaks = probe.measure(3);
              const GpuRun gpuRun = benchGpu(propagator, injected, options, bench.repeats);
              const double flops = bench::propagationFlopsPerCellStep(isotropic, gpuRun.steps);
              const double roof = std::min(peaks.fmaGflops, flops / kBytesPerCellStep * peaks.bandwidth());
              const double cellRate = active / (gpuRun.kernelMs * 1e-3);  // active cells per second
              const double gflops = cellRate * flops * 1e-9;
              const double cpuMs = bench.cpu ? benchCpu(material, factors, injected, options, bench.repeats) : 0.0;
              const std::string stepsText = steps > 0 ? std::to_string(steps) : "a" + std::to_string(gpuRun.steps);
              std::printf(
                  "%4d^3 %6s %14s %5s %8.0f %8zu %5zu | %8.3f %8.3f %8.3f %8.1f %7.2f %7.2f | %7.1f %6.2f %6.1f | %8.3f "
                  "%8.1f %7.2f\n",
                  n, shapeName(shape), variant.c_str(), stepsText.c_str(), active, propagator.coveredCells(),
                  propagator.itemCount(), gpuRun.kernelMs, gpuRun.wallMs, gpuRun.cpuMs, cellRate * 1e-6, gflops,
                  cellRate * kBytesPerCellStep * 1e-9, peaks.fmaGflops, peaks.bandwidth(), 100.0 * gflops / roof, cpuMs,
                  cpuMs > 0.0 ? active / (cpuMs * 1e3) : 0.0, cpuMs > 0.0 ? cpuMs / gpuRun.kernelMs : 0.0);
              std::fflush(stdout);
            }
          }
        }
      }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gpu_propagation_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}

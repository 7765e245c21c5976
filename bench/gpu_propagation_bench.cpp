// LPV propagation time per step, Vulkan backend against the CPU backend, on cubic grids
// whose interior cells are all active. Prints a table; not a test (no timing asserts).
//
//   gpu_propagation_bench [--sizes 32,64] [--steps 8] [--repeats 3] [--group XxY] [--zchunk N]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <sstream>
#include <string>
#include <vector>

#include "gpu/gpu_propagation.h"
#include "volume/lpv_constants.h"
#include "volume/lpv_stages.h"

namespace {
using namespace sslpv;

MaterialGrid uniformMaterial(int n) {
  MaterialGrid m;
  m.frame.dims = glm::ivec3(n);
  const std::size_t cells = m.frame.cellCount();
  m.coverage.assign(cells, 1.0f);
  m.sigmaT.assign(cells, glm::vec3(1.0f, 1.2f, 1.5f));
  m.sigmaS.assign(cells, glm::vec3(0.95f, 1.0f, 1.1f));
  m.g.assign(cells, 0.2f);
  return m;
}

/// Light everywhere (an isotropic part plus a tilt), so no cell takes a shortcut.
ShGrid litField(const MaterialGrid& m) {
  ShGrid field;
  field.resize(m.frame);
  for (std::size_t i = 0; i < m.frame.cellCount(); ++i)
    for (int ch = 0; ch < 3; ++ch) {
      field.plane(ch, 0)[i] = 1.0f + 0.01f * float(i % 7);
      field.plane(ch, 1)[i] = 0.3f;
      field.plane(ch, 3)[i] = -0.2f;
    }
  return field;
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

/// Processor time of the whole process (all threads, lavapipe's workers included): less
/// sensitive than wall time to other work on a shared machine.
double processCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

struct BenchOptions {
  std::vector<int> sizes{32, 64};
  int steps = 8, repeats = 3;
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

/// Flags come in pairs; std::invalid_argument names the one that is wrong.
BenchOptions parseOptions(int argc, char** argv) {
  BenchOptions options;
  if (argc % 2 == 0) throw std::invalid_argument(std::string("missing value after ") + argv[argc - 1]);
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--sizes") {
      options.sizes.clear();
      std::stringstream in(value);
      for (std::string item; std::getline(in, item, ',');) options.sizes.push_back(parseInt(flag, item));
    } else if (flag == "--steps") {
      options.steps = parseInt(flag, value);
    } else if (flag == "--repeats") {
      options.repeats = parseInt(flag, value);
    } else if (flag == "--zchunk") {
      options.gpu.zChunk = parseInt(flag, value);
    } else if (flag == "--group") {
      const std::size_t x = value.find('x');
      if (x == std::string::npos) throw std::invalid_argument("malformed value " + value + " for --group (XxY)");
      options.gpu.groupX = parseInt(flag, value.substr(0, x));
      options.gpu.groupY = parseInt(flag, value.substr(x + 1));
    } else {
      throw std::invalid_argument("unknown option " + flag);
    }
  }
  return options;
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
  const int steps = bench.steps, repeats = bench.repeats;
  try {
    gpu::VulkanDevice device;
    std::printf("device: %s, %d steps, best of %d\n", device.name().c_str(), steps, repeats);
    std::printf("%6s %7s %7s %12s %12s %12s %12s %12s %12s\n", "grid", "group", "zchunk", "gpu ms/step", "gpu Mcell/s",
                "gpu cpu-ms", "cpu ms/step", "cpu cpu-ms", "cpu/gpu");
    for (int n : bench.sizes) {
      const MaterialGrid material = uniformMaterial(n);
      const StepFactors factors = computeStepFactors(material);
      const ShGrid injected = litField(material);
      PropagationOptions options;
      options.steps = steps;

      gpu::GpuPropagator propagator(device, material.frame, factors, bench.gpu);
      // Per step: GPU timestamps, processor time of the GPU run (upload and readback
      // included), CPU wall time, processor time of the CPU run.
      double gpuStep = 1e30, gpuCpuTime = 1e30, cpuStep = 1e30, cpuCpuTime = 1e30;
      for (int r = 0; r < repeats + 1; ++r) {  // the first run pays for shader JIT
        ShGrid field = injected, accumulated;
        accumulated.resize(material.frame);
        const double cpuStart = processCpuSeconds();
        propagator.run(field, accumulated, options);
        if (r == 0) continue;
        gpuCpuTime = std::min(gpuCpuTime, (processCpuSeconds() - cpuStart) * 1e3 / steps);
        gpuStep = std::min(gpuStep, propagator.timings().propagateMsPerStep());
      }
      for (int r = 0; r < repeats; ++r) {
        ShGrid field = injected, accumulated;
        accumulated.resize(material.frame);
        const auto start = std::chrono::steady_clock::now();
        const double cpuStart = processCpuSeconds();
        propagate(material, factors, field, accumulated, options);
        cpuStep = std::min(cpuStep, seconds(start) * 1e3 / steps);
        cpuCpuTime = std::min(cpuCpuTime, (processCpuSeconds() - cpuStart) * 1e3 / steps);
      }
      const std::string group = std::to_string(propagator.groupX()) + "x" + std::to_string(propagator.groupY());
      std::printf("%5d^3 %7s %7d %12.2f %12.1f %12.2f %12.2f %12.2f %12.2f\n", n, group.c_str(), propagator.zChunk(),
                  gpuStep, double(material.frame.cellCount()) / gpuStep * 1e-3, gpuCpuTime, cpuStep, cpuCpuTime,
                  cpuStep / gpuStep);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gpu_propagation_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}

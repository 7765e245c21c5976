#include "volume/reference/slab_reflectance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "volume/core/quadrature.h"
#include "volume/reference/reference_tracer.h"
#include "volume/scene/scene.h"
#include "volume/core/math_constants.h"

namespace sslpv {
namespace {


}  // namespace

double dipoleRd(double albedoPrime, double eta) {
  const double fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
  const double a = (1.0 + fdr) / (1.0 - fdr);
  const double s = std::sqrt(3.0 * (1.0 - albedoPrime));
  return 0.5 * albedoPrime * (1.0 + std::exp(-4.0 / 3.0 * a * s)) * std::exp(-s);
}

double chandrasekharH(double mu, double albedo) {
  if (!(albedo >= 0.0 && albedo <= 1.0) || !(mu >= 0.0 && mu <= 1.0))
    throw std::invalid_argument("chandrasekharH: need albedo and mu in [0, 1]");
  // Chandrasekhar's iteration form 1/H(μ) = sqrt(1 - ω) + (ω/2) ∫0^1 μ' H(μ') / (μ + μ') dμ',
  // equivalent to H(μ) = 1 / (1 - (ω/2) μ ∫0^1 H(μ') / (μ + μ') dμ') but contracting
  // fast even near ω = 1, where the plain form converges slowly. Solved on the quadrature
  // nodes (Nyström), then evaluated at μ with the same quadrature.
  static const Quadrature q = gaussLegendreUnit(96);
  const std::size_t n = q.x.size();
  const double root = std::sqrt(1.0 - albedo);
  std::vector<double> h(n, 1.0), next(n);
  for (int iteration = 0; iteration < 10000; ++iteration) {
    double change = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      double integral = 0.0;
      for (std::size_t j = 0; j < n; ++j) integral += q.w[j] * q.x[j] * h[j] / (q.x[i] + q.x[j]);
      // Geometric mean with the previous iterate: at ω = 1 the map is blind to a constant
      // factor (H -> c·H gives 1/c times the image) and would oscillate forever; the mean
      // removes that mode and leaves the others contracting.
      next[i] = std::sqrt(h[i] / (root + 0.5 * albedo * integral));
      change = std::max(change, std::abs(next[i] - h[i]));
    }
    h.swap(next);
    if (change < 1e-14) break;
  }
  double integral = 0.0;
  for (std::size_t j = 0; j < n; ++j) integral += q.w[j] * q.x[j] * h[j] / (mu + q.x[j]);
  return 1.0 / (root + 0.5 * albedo * integral);
}

double exactIsotropicRd(double albedo) { return 1.0 - chandrasekharH(1.0, albedo) * std::sqrt(1.0 - albedo); }

SlabReflectance estimateSlabReflectance(const MaterialSample& material, double ior,
                                        const SlabReflectanceOptions& options) {
  if (options.samples < 2) throw std::invalid_argument("estimateSlabReflectance: need at least 2 samples");
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("estimateSlabReflectance: ior must be positive");
  if (!(options.size > 0.0)) throw std::invalid_argument("estimateSlabReflectance: size must be positive");
  const auto start = std::chrono::steady_clock::now();
  SlabReflectance result;
  std::vector<double> values(std::size_t(options.samples));
  for (int c = 0; c < 3; ++c) {
    const double sigmaT = material.sigmaT[c], sigmaS = material.sigmaS[c];
    if (!(sigmaT > 0.0)) continue;
    const double sigmaA = std::max(0.0, sigmaT - sigmaS);
    const double sigmaTPrime = sigmaA + sigmaS * (1.0 - double(material.g));
    const double sigmaTr = std::sqrt(3.0 * sigmaA * sigmaTPrime);
    // A (nearly) non-absorbing medium has no finite diffusion length: cap the slab at 1000
    // transport mean free paths times `size`, beyond which the tracer's relative ray
    // epsilon (2e-6 of the scene size) would approach a mean free path.
    const double unit =
        std::min(1000.0 / sigmaTPrime, std::max(1.0 / sigmaTPrime, sigmaTr > 0.0 ? 1.0 / sigmaTr : 1e300));
    const double length = options.size * unit;
    result.slabSize[c] = length;

    Scene scene;
    scene.mesh.kind = MeshSource::Kind::Box;
    scene.mesh.boxMin = glm::dvec3(-length, -length, -length);
    scene.mesh.boxMax = glm::dvec3(length, length, 0.0);
    scene.material.base = material;
    scene.material.ior = ior;
    Light light;
    light.type = Light::Type::Directional;
    light.direction = glm::dvec3(0.0, 0.0, -1.0);
    light.irradiance = glm::vec3(1.0f);
    scene.lights.push_back(light);
    const ReferenceTracer tracer(scene, nullptr);

    // Far enough above the face that the tracer's ray epsilon (2e-6 of the scene size)
    // never skips it, close enough that a cosine-distributed ray misses the face only
    // with probability (1e-4 / 1)^2.
    const glm::dvec3 origin(0.0, 0.0, 1e-4 * length);
    auto work = [&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, options.samples, 256), [&](const tbb::blocked_range<int>& range) {
        for (int i = range.begin(); i < range.end(); ++i) {
          ReferenceRng rng(options.seed, std::uint64_t(c), std::uint64_t(i));
          const double u1 = rng.uniform(), u2 = rng.uniform();
          const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
          const glm::dvec3 up(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)));
          values[std::size_t(i)] = kPi * tracer.radianceSample(origin, -up, c, rng, options.maxScatterEvents);
        }
      });
    };
    if (options.threads > 0) {
      tbb::task_arena arena(options.threads);
      arena.execute(work);
    } else {
      work();
    }
    // Summed in index order: the result does not depend on the thread count.
    double sum = 0.0, sumSq = 0.0;
    for (const double v : values) {
      sum += v;
      sumSq += v * v;
    }
    const double n = options.samples;
    const double mean = sum / n;
    result.rd[c] = mean;
    result.standardError[c] = std::sqrt(std::max(0.0, (sumSq - n * mean * mean) / (n - 1.0)) / n);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace sslpv

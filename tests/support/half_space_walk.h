#pragma once
// An analog Monte Carlo random walk for the reflectance of a half-space or slab behind a smooth
// dielectric boundary, independent of the reference tracer and of the adding-doubling
// solver: both are checked against it (slab_reflectance_test, adding_doubling_test).
#include <cmath>
#include <cstdint>
#include <limits>

#include "volume/core/fresnel.h"
#include "volume/reference/reference_tracer.h"

namespace sslpv::test {

/// What a slab `thickness` mean free paths thick (σt = 1; infinite: a half-space), with the
/// same smooth boundary of relative index eta on both faces, reflects and transmits of a
/// collimated beam: an analog random walk in depth and direction cosine only, with nothing
/// in common with the tracer but fresnelReflectance. The beam runs at `beamCosine` to the
/// normal inside (after refraction; 1: normal incidence). Specular reflection at entry is
/// not counted; light leaving through the far face without having scattered (the beam's
/// unscattered remainder) is counted apart, as `direct`.
struct SlabWalk {
  double reflected = 0.0, transmitted = 0.0, direct = 0.0;
  double reflectedError = 0.0, transmittedError = 0.0;
};
inline SlabWalk slabWalk(double albedo, double eta, double thickness, int photons, std::uint64_t seed,
                         double beamCosine = 1.0) {
  ReferenceRng rng(seed, 0, 0);
  const double cosOutside = std::sqrt(1.0 - eta * eta * (1.0 - beamCosine * beamCosine));
  const double f0 = fresnelReflectance(cosOutside, eta);
  long long reflected = 0, transmitted = 0, direct = 0;
  for (int k = 0; k < photons; ++k) {
    if (rng.uniform() < f0) continue;
    double z = 0.0, mu = beamCosine;  // depth, and direction cosine with +z pointing down
    bool scattered = false;
    while (true) {
      z -= std::log(1.0 - rng.uniform()) * mu;
      if (z < 0.0 || z > thickness) {
        const double sin2T = eta * eta * (1.0 - mu * mu);
        const double reflect = sin2T >= 1.0 ? 1.0 : fresnelReflectance(std::sqrt(1.0 - sin2T), eta);
        if (rng.uniform() < reflect) {  // mirrored back in; the flight restarts at the face
          z = z < 0.0 ? 0.0 : thickness;
          mu = -mu;
          continue;
        }
        if (z < 0.0)
          ++reflected;
        else if (scattered)
          ++transmitted;
        else
          ++direct;
        break;
      }
      if (rng.uniform() >= albedo) break;
      mu = 1.0 - 2.0 * rng.uniform();
      scattered = true;
    }
  }
  SlabWalk w;
  w.reflected = double(reflected) / photons;
  w.transmitted = double(transmitted) / photons;
  w.direct = double(direct) / photons;
  w.reflectedError = std::sqrt(w.reflected * (1.0 - w.reflected) / photons);
  w.transmittedError = std::sqrt(w.transmitted * (1.0 - w.transmitted) / photons);
  return w;
}

/// Reflected fraction of a collimated beam on the half-space: slabWalk without a far face.
inline double halfSpaceWalk(double albedo, double eta, int photons, std::uint64_t seed, double& standardError,
                            double beamCosine = 1.0) {
  const SlabWalk walk =
      slabWalk(albedo, eta, std::numeric_limits<double>::infinity(), photons, seed, beamCosine);
  standardError = walk.reflectedError;
  return walk.reflected;
}

}  // namespace sslpv::test

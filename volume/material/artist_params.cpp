// Artist parameters <-> σt, σs, g (conventions and the choice of distance in artist_params.h).
#include "volume/material/artist_params.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "volume/core/error.h"
#include "volume/core/fresnel.h"
#include "volume/calibration/lpv_calibration.h"

namespace sslpv {
namespace {

std::string formatValue(double x) {
  char text[48];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

std::string indexed(const char* key, int c) { return std::string(key) + "[" + std::to_string(c) + "]"; }

std::string colourProblem(double colour, double ior) {
  const double cmax = maxSurfaceColour(ior);
  if (std::isfinite(colour) && colour >= 0.0 && colour <= cmax) return {};
  std::string text = "must be in [0, " + formatValue(cmax) + "], got " + formatValue(colour);
  if (std::isfinite(colour) && colour > cmax)
    text += " (" + formatValue(cmax) + " is the brightest a medium that absorbs nothing shows behind an ior " +
            formatValue(ior) + " boundary)";
  return text;
}

}  // namespace

double maxSurfaceColour(double ior) {
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("maxSurfaceColour: ior must be positive");
  return 1.0 - fresnelReflectance(1.0, ior);
}

double reducedAlbedoForColour(double colour, double ior) {
  if (std::string problem = colourProblem(colour, ior); !problem.empty())
    throw InputError("surface colour " + problem);
  if (colour == 0.0) return 0.0;
  if (colour == maxSurfaceColour(ior)) return 1.0;
  // Bisection over s = sqrt(1 - α'), the table's own variable: Rd falls steadily with s,
  // whereas over α' it steepens without bound at α' -> 1, where the bright colours are.
  double lo = 0.0, hi = 1.0;  // Rd(lo) >= colour >= Rd(hi)
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (boundaryReflectance(1.0 - mid * mid, ior) >= colour ? lo : hi) = mid;
  }
  const double s = 0.5 * (lo + hi);
  return 1.0 - s * s;
}

std::string artistParamsProblem(const ArtistParams& p, double ior) {
  for (int c = 0; c < 3; ++c)
    if (std::string problem = colourProblem(p.colour[c], ior); !problem.empty())
      return indexed("colour", c) + ": " + problem;
  for (int c = 0; c < 3; ++c) {
    const double d = p.scatterDistance[c];
    if (!(d > 0.0) || !std::isfinite(d))
      return indexed("scatter_distance", c) + ": must be positive and finite, got " + formatValue(d);
    // σs = α' / (d (1 - g)) must stay a finite float at any accepted g.
    if (d < kMinScatterDistance)
      return indexed("scatter_distance", c) + ": must be at least " + formatValue(kMinScatterDistance) + ", got " +
             formatValue(d);
  }
  if (!(std::abs(p.g) <= kArtistMaxG)) return "g: must be in [-0.99, 0.99], got " + formatValue(p.g);
  return {};
}

MaterialSample artistToPhysical(const ArtistParams& p, double ior) {
  if (std::string problem = artistParamsProblem(p, ior); !problem.empty()) throw InputError(problem);
  MaterialSample m;
  m.g = float(p.g);
  for (int c = 0; c < 3; ++c) {
    const double albedo = reducedAlbedoForColour(p.colour[c], ior);
    const double reducedSigmaT = 1.0 / p.scatterDistance[c];
    const double sigmaA = (1.0 - albedo) * reducedSigmaT;
    const double sigmaS = albedo * reducedSigmaT / (1.0 - p.g);
    m.sigmaT[c] = float(sigmaA + sigmaS);
    m.sigmaS[c] = float(sigmaS);
  }
  return m;
}

ArtistParams physicalToArtist(const MaterialSample& m, double ior) {
  ArtistParams p;
  p.g = m.g;
  for (int c = 0; c < 3; ++c) {
    const double sigmaT = std::max(0.0, double(m.sigmaT[c]));
    const double sigmaS = std::min(std::max(0.0, double(m.sigmaS[c])), sigmaT);
    const double reducedS = sigmaS * (1.0 - double(m.g));
    const double reducedT = (sigmaT - sigmaS) + reducedS;
    if (!(reducedT > 0.0)) {
      p.colour[c] = 0.0;
      p.scatterDistance[c] = HUGE_VAL;
      continue;
    }
    p.colour[c] = boundaryReflectance(std::min(1.0, reducedS / reducedT), ior);
    p.scatterDistance[c] = 1.0 / reducedT;
  }
  return p;
}

}  // namespace sslpv

// Calibrated SSLPV transport; the model and its reasons are in lpv_calibration.h.
//
// Derivation of the lattice's shaded reflectance R_lpv (semi-infinite layer stack n = 1,
// 2, ..., light injected into layer 1 as a cosine lobe pointing inward, layer 0 outside):
//  - step 1 sends the fractions (f_up, f_lat, f_down) of the lobe's power out, into layer
//    1 and into layer 2, each then multiplied by s;
//  - from then on cells are isotropic and every step moves 1/6 up, 1/6 down, 4/6 within
//    the layer, times s. The power w(n) accumulated in layer n over all later steps
//    solves  a w(n) - b (w(n-1) + w(n+1)) = q(n), a = 1 - 4s/6, b = s/6, w(0) = 0,
//    whose Green's function (method of images) is
//      G(n, m) = (r^|n-m| - r^(n+m)) / (b (1/r - r)),  r + 1/r = a/b = 6/s - 4;
//    with q(1) = s f_lat, q(2) = s f_down this gives w(1) = 6 r (f_lat + r f_down).
//  - the injected lobe itself integrates to zero over the outward hemisphere, and the
//    shading turns an isotropic cell of power P into radiance P / (2 π Δx²); with
//    irradiance E the injected power per cell is E Δx², so π L / E = w(1) / 2.
#include "volume/lpv_calibration.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "volume/lpv_constants.h"
#include "volume/lpv_stages.h"
#include "volume/slab_reflectance.h"

namespace sslpv {
namespace {

constexpr int kReflectanceTable = 128;  // entries over t = sqrt(1 - albedo) in [0, 1]

const std::vector<double>& reflectanceTable() {
  static std::vector<double> table;
  static std::once_flag once;
  std::call_once(once, [] {
    table.resize(kReflectanceTable + 1);
    for (int i = 0; i <= kReflectanceTable; ++i) {
      const double t = double(i) / kReflectanceTable;
      table[i] = exactIsotropicRd(1.0 - t * t);
    }
  });
  return table;
}

}  // namespace

bool parseLpvScheme(std::string_view name, LpvScheme& scheme) {
  if (name == "seed") {
    scheme = LpvScheme::Seed;
    return true;
  }
  if (name == "calibrated") {
    scheme = LpvScheme::Calibrated;
    return true;
  }
  return false;
}

std::string lpvSchemeName(LpvScheme scheme) { return scheme == LpvScheme::Seed ? "seed" : "calibrated"; }

double halfSpaceReflectance(double albedo) {
  const std::vector<double>& table = reflectanceTable();
  const double t = std::sqrt(std::clamp(1.0 - albedo, 0.0, 1.0)) * kReflectanceTable;
  const int i = std::min(int(t), kReflectanceTable - 1);
  const double f = t - i;
  return (1.0 - f) * table[i] + f * table[i + 1];
}

std::array<double, 3> injectedLobeSplit() {
  // A lobe pointing into the medium along -z; its neighbours in the order -x,+x,-y,+y,-z,+z.
  const std::array<float, 6> flux = neighbourFaceFlux(float(SSLPV_COSINE_LOBE_C0), 0.0f, 0.0f,
                                                      -float(SSLPV_COSINE_LOBE_C1));
  double total = 0.0;
  for (float f : flux) total += f;
  return {flux[5] / total, (flux[0] + flux[1] + flux[2] + flux[3]) / total, flux[4] / total};
}

CellTransport seedTransport(double sigmaT, double sigmaS, double g, double cellSize) {
  const double e = std::exp(-sigmaT * cellSize);
  // Albedo of an empty cell is irrelevant (e = 1); guard the 0/0.
  const double albedo = sigmaT > 0.0 ? std::min(1.0, sigmaS / sigmaT) : 1.0;
  const double scattered = albedo * (1.0 - e);
  return {float(e + scattered), float(e + scattered * g), 1.0f};
}

CellTransport calibratedTransport(double sigmaT, double sigmaS, double g, double cellSize, double ior) {
  static const std::array<double, 3> split = injectedLobeSplit();
  const double sigmaA = std::max(0.0, sigmaT - sigmaS);
  const double reducedS = std::max(0.0, sigmaS) * (1.0 - g);
  const double reducedT = sigmaA + reducedS;
  const double sigmaTr = std::sqrt(3.0 * sigmaA * reducedT);
  const double kappa = sigmaTr * cellSize;
  // cosh overflows far beyond any useful κ; such a cell absorbs everything in one step.
  const double survival = kappa < 700.0 ? 3.0 / (2.0 + std::cosh(kappa)) : 0.0;
  const double r = std::exp(-kappa);
  const double latticeReflectance = 3.0 * r * (split[1] + r * split[2]);
  const double reducedAlbedo = reducedT > 0.0 ? reducedS / reducedT : 1.0;
  const double target = halfSpaceReflectance(reducedAlbedo) *
                        (dipoleRd(reducedAlbedo, ior) / dipoleRd(reducedAlbedo, 1.0));
  double gain = latticeReflectance > 0.0 ? ior * ior * target / latticeReflectance : 0.0;
  if (!std::isfinite(gain) || reducedAlbedo <= 0.0) gain = 0.0;
  return {float(survival), 0.0f, float(gain)};
}

}  // namespace sslpv

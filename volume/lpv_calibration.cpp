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
//  - with a boundary of relative index η the injection has already multiplied E by
//    1 - F(0) and the shading multiplies the radiance by (1 - F(θ)) / η², so the power the
//    lattice reflects is exitGain · R_lpv · (1 - F(0)) · T, T = 2 ∫ (1 - F(θ)) cos θ dcos θ / η²
//    over the outside hemisphere (diffuseBoundaryTransmittance: the share of an isotropic
//    field inside that crosses the boundary).
#include "volume/lpv_calibration.h"

#include "volume/exit_law.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "volume/adding_doubling.h"
#include "volume/fresnel.h"
#include "volume/lpv_constants.h"
#include "volume/lpv_stages.h"

namespace sslpv {
namespace {

constexpr int kReflectanceTable = 128;  // intervals over t = sqrt(1 - albedo) in [0, 1]

/// boundaryReflectance for one ior: Rd / albedo at t = i / kReflectanceTable. Dividing by
/// the albedo keeps the relative interpolation error small at low albedo, where Rd -> 0 as
/// fast as the albedo (single scattering).
struct BoundaryTable {
  double ior = 1.0;
  std::vector<double> rdOverAlbedo;
  double entering = 1.0;  ///< 1 - F(0): the injection's share of normal irradiance
  double leaving = 1.0;   ///< diffuseBoundaryTransmittance(ior): the shading's exit share
};

std::unique_ptr<const BoundaryTable> buildBoundaryTable(double ior) {
  auto table = std::make_unique<BoundaryTable>();
  table->ior = ior;
  table->rdOverAlbedo.resize(kReflectanceTable + 1);
  for (int i = 0; i <= kReflectanceTable; ++i) {
    const double t = double(i) / kReflectanceTable;
    // t = 0: a non-absorbing half-space returns all the light that enters it (the solver
    // gets there only as 1/thickness). t = 1: the albedo -> 0 limit of Rd / albedo, which
    // Rd at albedo 1e-9 gives to a relative 1e-9.
    const double albedo = i == 0 ? 1.0 : std::max(1e-9, 1.0 - t * t);
    table->rdOverAlbedo[std::size_t(i)] =
        i == 0 ? 1.0 - fresnelReflectance(1.0, ior) : addingDoublingHalfSpace(albedo, ior).rd / albedo;
  }
  table->entering = 1.0 - fresnelReflectance(1.0, ior);
  table->leaving = diffuseBoundaryTransmittance(ior);
  return table;
}

/// Built once per ior on first use, kept for the process (a scene has one ior; the editor
/// a few). The thread-local pointer skips the lock for the per-cell calls.
const BoundaryTable& boundaryTable(double ior) {
  thread_local const BoundaryTable* last = nullptr;
  if (last != nullptr && last->ior == ior) return *last;
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("boundaryReflectance: ior must be positive");
  static std::mutex mutex;
  static std::map<double, std::unique_ptr<const BoundaryTable>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<const BoundaryTable>& slot = tables[ior];
  if (!slot) slot = buildBoundaryTable(ior);
  last = slot.get();
  return *last;
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

double boundaryReflectance(double albedo, double ior) {
  const std::vector<double>& table = boundaryTable(ior).rdOverAlbedo;
  albedo = std::clamp(albedo, 0.0, 1.0);
  // Cubic through the 4 nearest nodes: linear interpolation would be off by up to 4e-4
  // relative near albedo 1 at η = 1.5, where Rd / albedo bends fastest in t.
  const double t = std::sqrt(1.0 - albedo) * kReflectanceTable;
  const int first = std::clamp(int(t) - 1, 0, kReflectanceTable - 3);
  const double x = t - first;
  const double weights[4] = {-(x - 1.0) * (x - 2.0) * (x - 3.0) / 6.0, x * (x - 2.0) * (x - 3.0) / 2.0,
                             -x * (x - 1.0) * (x - 3.0) / 2.0, x * (x - 1.0) * (x - 2.0) / 6.0};
  double value = 0.0;
  for (int k = 0; k < 4; ++k) value += weights[k] * table[std::size_t(first + k)];
  return albedo * value;
}

double halfSpaceReflectance(double albedo) { return boundaryReflectance(albedo, 1.0); }

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
  // The injection has already taken 1 - F(0) of the irradiance and the shading lets out
  // `leaving` of an isotropic cell's power, so this gain makes the lattice reflect the
  // medium's Rd in total.
  const BoundaryTable& boundary = boundaryTable(ior);
  const double target = boundaryReflectance(reducedAlbedo, ior) / (boundary.entering * boundary.leaving);
  double gain = latticeReflectance > 0.0 ? target / latticeReflectance : 0.0;
  if (!std::isfinite(gain) || reducedAlbedo <= 0.0) gain = 0.0;
  return {float(survival), 0.0f, float(gain), float(reducedAlbedo)};
}

void prepareCalibrationTables(double ior) {
  boundaryReflectance(1.0, ior);
  exitLawTable(ior);
}

}  // namespace sslpv

// The calibrated exit law's table; the model and its reasons are in exit_law.h.
#include "volume/calibration/exit_law.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "volume/calibration/adding_doubling.h"
#include "volume/core/fresnel.h"
#include "device_shared/lpv_constants.h"
#include "volume/core/quadrature.h"

namespace sslpv {
namespace {

constexpr int kMu = SSLPV_EXIT_LAW_MU_INTERVALS;
constexpr int kAlbedo = SSLPV_EXIT_LAW_ALBEDO_INTERVALS;
// Nodes of the adding-doubling solutions behind the table: 16 escaping directions for
// η > 1 (32 for η <= 1), through which the radiance is interpolated.
constexpr int kNodes = 32;
// α' = 0 has no exitant light to take a shape from; its shape is the limit α' -> 0
// (single scattering), which this albedo gives to ~1e-7.
constexpr double kSmallestAlbedo = 1e-7;

void checkIor(double ior) {
  if (!(ior > 0.0) || !std::isfinite(ior)) throw std::invalid_argument("exit law: ior must be positive and finite");
}

/// 1 - F for light leaving at outside cosine mu (Fresnel is reciprocal; 0 where no inside
/// direction refracts into mu, η < 1).
double exitTransmittance(double mu, double eta) { return 1.0 - fresnelReflectance(mu, eta); }

/// ∫0^1 f(μo) dμo by 16-point Gauss on `panels` equal panels, each split where 1 - F(μo)
/// has its kink (η < 1: μo = sqrt(1 - η²), below which nothing leaves).
template <class F>
double integrateOutside(double eta, int panels, const F& f) {
  static const Quadrature gauss = gaussLegendreUnit(16);
  const double kink = eta < 1.0 ? std::sqrt(1.0 - eta * eta) : -1.0;
  double sum = 0.0;
  auto piece = [&](double a, double b) {
    for (std::size_t i = 0; i < gauss.x.size(); ++i) sum += (b - a) * gauss.w[i] * f(a + (b - a) * gauss.x[i]);
  };
  for (int p = 0; p < panels; ++p) {
    const double a = double(p) / panels, b = double(p + 1) / panels;
    if (kink > a && kink < b) {
      piece(a, kink);
      piece(kink, b);
    } else {
      piece(a, b);
    }
  }
  return sum;
}

/// 2 ∫0^1 T(μo)/η² h(μo) μo dμo for h given at the table's μo nodes, linear between them:
/// the coefficient of each node's value (hat function), so a row's power is one dot product.
std::vector<double> hatPower(double eta) {
  std::vector<double> power(kMu + 1, 0.0);
  for (int j = 0; j <= kMu; ++j) {
    const double node = double(j) / kMu;
    power[std::size_t(j)] = integrateOutside(eta, kMu, [&](double mu) {
      const double hat = std::max(0.0, 1.0 - std::abs(mu - node) * kMu);
      return 2.0 * exitTransmittance(mu, eta) / (eta * eta) * hat * mu;
    });
  }
  return power;
}

}  // namespace

ExitLawTable buildExitLawTable(double ior) {
  checkIor(ior);
  const auto start = std::chrono::steady_clock::now();
  ExitLawTable table;
  table.ior = ior;
  table.shape.resize(std::size_t(kAlbedo + 1) * (kMu + 1));
  const std::vector<double> hat = hatPower(ior);
  double lambertian = 0.0;  // the old law's power, h = 1, in the same quadrature
  for (double c : hat) lambertian += c;
  for (int k = 0; k <= kAlbedo; ++k) {
    const double t = double(k) / kAlbedo;
    const ExactExitShape radiance(1.0 - t * t, ior, kNodes);
    std::vector<double> row(kMu + 1);
    double power = 0.0;
    for (int j = 0; j <= kMu; ++j) {
      row[std::size_t(j)] = radiance(double(j) / kMu);
      power += hat[std::size_t(j)] * row[std::size_t(j)];
    }
    // Scaling the row itself (not the continuous shape) makes the bilinear interpolant
    // carry exactly the old law's power at every α'.
    for (int j = 0; j <= kMu; ++j)
      table.shape[std::size_t(k) * (kMu + 1) + std::size_t(j)] = float(row[std::size_t(j)] * lambertian / power);
  }
  table.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return table;
}

const ExitLawTable& exitLawTable(double ior) {
  thread_local const ExitLawTable* last = nullptr;
  if (last != nullptr && last->ior == ior) return *last;
  checkIor(ior);
  static std::mutex mutex;
  static std::map<double, std::unique_ptr<const ExitLawTable>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<const ExitLawTable>& slot = tables[ior];
  if (!slot) slot = std::make_unique<const ExitLawTable>(buildExitLawTable(ior));
  last = slot.get();
  return *last;
}

float exitLawRow(float reducedAlbedo) {
  return std::sqrt(std::clamp(1.0f - reducedAlbedo, 0.0f, 1.0f)) * float(kAlbedo);
}

ExitLawColumn exitLawColumn(float cosOut) {
  const float m = std::clamp(cosOut, 0.0f, 1.0f) * float(kMu);
  const int j = std::min(int(m), kMu - 1);
  return {j, m - float(j)};
}

float exitLawShapeAt(const ExitLawTable& table, float t, ExitLawColumn column) {
  const int k = std::min(int(t), kAlbedo - 1);
  const float ft = t - float(k);
  const float fm = column.fraction;
  const float* low = table.shape.data() + std::size_t(k) * (kMu + 1) + std::size_t(column.index);
  const float* high = low + (kMu + 1);
  const float a = low[0] + fm * (low[1] - low[0]);
  const float b = high[0] + fm * (high[1] - high[0]);
  return a + ft * (b - a);
}

float exitLawShape(const ExitLawTable& table, float reducedAlbedo, float cosOut) {
  // Keep this line for line with exitLawShape in shaders/shade.comp.
  return exitLawShapeAt(table, exitLawRow(reducedAlbedo), exitLawColumn(cosOut));
}

double exitRadianceFactor(const ExitLawTable& table, double reducedAlbedo, double cosOut) {
  return exitTransmittance(std::clamp(cosOut, 0.0, 1.0), table.ior) / (table.ior * table.ior) *
         double(exitLawShape(table, float(reducedAlbedo), float(cosOut)));
}

ExactExitShape::ExactExitShape(double reducedAlbedo, double ior, int nodes) : eta_(ior) {
  checkIor(ior);
  AddingDoublingOptions options;
  options.nodes = nodes;
  const double albedo = std::clamp(reducedAlbedo, kSmallestAlbedo, 1.0);
  const HalfSpaceReflectance solution = addingDoublingHalfSpace(albedo, ior, options);
  muC_ = ior > 1.0 ? std::sqrt(1.0 - 1.0 / (ior * ior)) : 0.0;
  // With explicit single scattering the lattice carries only the light that scattered
  // more than once: the once-scattered radiance arriving from below, 2π L₁ = α' (1 − F(0))
  // / (2 (1 + μ)) per unit irradiance, is not its to shape.
  const double single = albedo * (1.0 - fresnelReflectance(1.0, ior));
  for (std::size_t i = 0; i < solution.mu.size(); ++i) {
    const double mu = solution.mu[i];
    if (mu <= muC_) continue;  // totally reflected: never leaves
    x_.push_back(variable(mu));
    y_.push_back(std::max(0.0, solution.upward[i] / (solution.weight[i] * mu) - single / (2.0 * (1.0 + mu))));
  }
  // Where nothing is left after the once-scattered light (α' -> 0), the shape of what
  // little remains is immaterial: keep it Lambertian rather than divide by zero.
  if (*std::max_element(y_.begin(), y_.end()) <= 0.0) std::fill(y_.begin(), y_.end(), 1.0);
  // Barycentric weights 1 / Π (x_j - x_k): the nodes are Gauss points in the variable,
  // which keeps the polynomial interpolant well conditioned.
  for (std::size_t j = 0; j < x_.size(); ++j) {
    double product = 1.0;
    for (std::size_t k = 0; k < x_.size(); ++k)
      if (k != j) product *= x_[j] - x_[k];
    w_.push_back(1.0 / product);
  }
  auto power = [&](auto h) {
    return integrateOutside(ior, 256, [&](double mu) { return 2.0 * exitTransmittance(mu, ior) * h(mu) * mu; });
  };
  scale_ = power([](double) { return 1.0; }) / power([&](double mu) { return radiance(mu); });
}

double ExactExitShape::operator()(double cosOut) const { return scale_ * radiance(std::clamp(cosOut, 0.0, 1.0)); }

double ExactExitShape::radiance(double cosOut) const {
  const double sin2In = (1.0 - cosOut * cosOut) / (eta_ * eta_);
  const double x = variable(std::sqrt(std::max(0.0, 1.0 - sin2In)));
  double numerator = 0.0, denominator = 0.0;
  for (std::size_t j = 0; j < x_.size(); ++j) {
    if (x == x_[j]) return y_[j];
    const double c = w_[j] / (x - x_[j]);
    numerator += c * y_[j];
    denominator += c;
  }
  return numerator / denominator;
}

// μ, or for η > 1 the s of μ = μc + (1 - μc)s²: the adding-doubling nodes are Gauss points
// in it, and μo ∝ s near grazing exit.
double ExactExitShape::variable(double mu) const {
  return eta_ > 1.0 ? std::sqrt(std::max(0.0, (mu - muC_) / (1.0 - muC_))) : mu;
}

}  // namespace sslpv

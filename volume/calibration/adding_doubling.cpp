// Adding-doubling for a semi-infinite isotropic medium behind a Fresnel boundary; the
// method is described in adding_doubling.h.
//
// Conventions: n bins, matrices row-major n x n, entry (i, j) = power arriving in bin i per
// unit power incident in bin j, so a column sum is the power a bin's light keeps. The
// collimated beam, not a node, is one more column beside them (r0, t0) plus its unscattered
// fraction. The result is the exact solution of the discrete-ordinate equations in the
// chosen nodes: the starting layer is exact (thinLayer) and doubling is exact algebra, so
// the only approximation is the quadrature, which converges spectrally in the nodes.
#include "volume/calibration/adding_doubling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "volume/core/fresnel.h"
#include "volume/core/quadrature.h"

namespace sslpv {
namespace {

/// Fresnel reflectance of light inside the medium arriving at the boundary with direction
/// cosine mu: 1 beyond the critical angle, else that of the refracted pair (reciprocity).
double internalFresnel(double mu, double eta) {
  if (eta == 1.0) return 0.0;
  const double sin2Out = eta * eta * (1.0 - mu * mu);
  if (sin2Out >= 1.0) return 1.0;
  return fresnelReflectance(std::sqrt(1.0 - sin2Out), eta);
}

/// Direction cosines inside the medium: Gauss on [0, 1], or for η > 1 Gauss on [0, μc]
/// and Gauss in s on μ = μc + (1 - μc) s² (see the header).
void boundaryQuadrature(int n, double eta, std::vector<double>& mu, std::vector<double>& weight) {
  if (eta <= 1.0) {
    Quadrature q = gaussLegendreUnit(n);
    mu = std::move(q.x);
    weight = std::move(q.w);
    return;
  }
  const double muC = std::sqrt(1.0 - 1.0 / (eta * eta));
  const int lower = n / 2, upper = n - lower;
  mu.clear();
  weight.clear();
  const Quadrature below = gaussLegendreUnit(lower);
  for (int i = 0; i < lower; ++i) {
    mu.push_back(muC * below.x[std::size_t(i)]);
    weight.push_back(muC * below.w[std::size_t(i)]);
  }
  const Quadrature above = gaussLegendreUnit(upper);
  for (int i = 0; i < upper; ++i) {
    const double s = above.x[std::size_t(i)];
    mu.push_back(muC + (1.0 - muC) * s * s);
    weight.push_back((1.0 - muC) * 2.0 * s * above.w[std::size_t(i)]);
  }
}

/// Dense row-major square matrices, just what doubling needs.
struct Matrix {
  int n = 0;
  std::vector<double> a;
  explicit Matrix(int size) : n(size), a(std::size_t(size) * std::size_t(size), 0.0) {}
  double& operator()(int i, int j) { return a[std::size_t(i) * std::size_t(n) + std::size_t(j)]; }
  double operator()(int i, int j) const { return a[std::size_t(i) * std::size_t(n) + std::size_t(j)]; }
};

/// out = x * y (out must not alias x or y).
void multiply(const Matrix& x, const Matrix& y, Matrix& out) {
  const int n = x.n;
  std::fill(out.a.begin(), out.a.end(), 0.0);
  for (int i = 0; i < n; ++i) {
    double* row = &out.a[std::size_t(i) * std::size_t(n)];
    for (int k = 0; k < n; ++k) {
      const double xik = x(i, k);
      const double* yRow = &y.a[std::size_t(k) * std::size_t(n)];
      for (int j = 0; j < n; ++j) row[j] += xik * yRow[j];
    }
  }
}

std::vector<double> multiply(const Matrix& x, const std::vector<double>& v) {
  std::vector<double> out(std::size_t(x.n), 0.0);
  for (int i = 0; i < x.n; ++i)
    for (int j = 0; j < x.n; ++j) out[std::size_t(i)] += x(i, j) * v[std::size_t(j)];
  return out;
}

/// LU factorisation with partial pivoting, in place; then solves in place.
class Lu {
 public:
  explicit Lu(Matrix m) : lu_(std::move(m)), pivot_(std::size_t(lu_.n)) {
    const int n = lu_.n;
    for (int k = 0; k < n; ++k) {
      int p = k;
      for (int i = k + 1; i < n; ++i)
        if (std::abs(lu_(i, k)) > std::abs(lu_(p, k))) p = i;
      pivot_[std::size_t(k)] = p;
      if (p != k)
        for (int j = 0; j < n; ++j) std::swap(lu_(k, j), lu_(p, j));
      const double inverse = 1.0 / lu_(k, k);
      for (int i = k + 1; i < n; ++i) {
        const double factor = lu_(i, k) *= inverse;
        for (int j = k + 1; j < n; ++j) lu_(i, j) -= factor * lu_(k, j);
      }
    }
  }

  /// Overwrites every column of b with the solution of (this) x = column.
  void solve(Matrix& b) const {
    const int n = lu_.n;
    for (int k = 0; k < n; ++k) {
      const int p = pivot_[std::size_t(k)];
      if (p != k)
        for (int j = 0; j < n; ++j) std::swap(b(k, j), b(p, j));
    }
    for (int k = 0; k < n; ++k)
      for (int i = k + 1; i < n; ++i) {
        const double factor = lu_(i, k);
        for (int j = 0; j < n; ++j) b(i, j) -= factor * b(k, j);
      }
    for (int k = n - 1; k >= 0; --k) {
      const double inverse = 1.0 / lu_(k, k);
      for (int j = 0; j < n; ++j) b(k, j) *= inverse;
      for (int i = 0; i < k; ++i) {
        const double factor = lu_(i, k);
        for (int j = 0; j < n; ++j) b(i, j) -= factor * b(k, j);
      }
    }
  }

  void solve(std::vector<double>& b) const {
    const int n = lu_.n;
    for (int k = 0; k < n; ++k) std::swap(b[std::size_t(k)], b[std::size_t(pivot_[std::size_t(k)])]);
    for (int k = 0; k < n; ++k)
      for (int i = k + 1; i < n; ++i) b[std::size_t(i)] -= lu_(i, k) * b[std::size_t(k)];
    for (int k = n - 1; k >= 0; --k) {
      b[std::size_t(k)] /= lu_(k, k);
      for (int i = 0; i < k; ++i) b[std::size_t(i)] -= lu_(i, k) * b[std::size_t(k)];
    }
  }

 private:
  Matrix lu_;
  std::vector<int> pivot_;
};

/// Reflection and transmission of a layer of optical thickness `delta`, exact for the
/// discrete-ordinate equations. With f+ (f-) the downward (upward) power per bin and b the
/// beam at direction cosine μ0, d/dτ [f+, f-, b] = K [f+, f-, b] with
///   K = [[S - D, S, s], [-S, D - S, -s], [0, 0, -1/μ0]],  D = diag(1/μ), S_ij = ω w_i / (2 μ_j),
/// s_i = ω w_i / (2 μ0) (scattered power per unit depth, isotropic: half into each hemisphere,
/// shared by solid angle 2π w_i). M = exp(δK) by its Taylor series; nothing enters from
/// below (f-(δ) = 0) gives R = -M22^-1 M21 and T = M11 + M12 R, the beam's columns alike.
/// For ω = 1, [1, -1, 1]ᵀ K = 0, so every Taylor term conserves power: the starting layer
/// neither gains nor loses any, which doubling to great thickness needs.
void thinLayer(double albedo, const std::vector<double>& mu, const std::vector<double>& w, double beamCosine,
               double delta, Matrix& r, Matrix& t, std::vector<double>& r0, std::vector<double>& t0) {
  // δK = Λ + p qᵀ: diagonal extinction plus rank-one isotropic scattering, with
  // Λ = δ diag(-1/μ, 1/μ, -1), p = (w, -w, 0), q = δ (ω/2) (1/μ, 1/μ, 1). So each Taylor
  // term costs O(m²): (X δK)_ij = X_ij Λ_j + (X p)_i q_j.
  const int n = int(mu.size()), m = 2 * n + 1;
  const std::size_t size = std::size_t(m);
  std::vector<double> lambda(size), p(size, 0.0), q(size);
  for (int i = 0; i < n; ++i) {
    lambda[std::size_t(i)] = -delta / mu[std::size_t(i)];
    lambda[std::size_t(n + i)] = delta / mu[std::size_t(i)];
    p[std::size_t(i)] = w[std::size_t(i)];
    p[std::size_t(n + i)] = -w[std::size_t(i)];
    q[std::size_t(i)] = q[std::size_t(n + i)] = delta * 0.5 * albedo / mu[std::size_t(i)];
  }
  // The beam crosses 1/μ0 of path per unit depth: it is extinguished and scatters that much.
  lambda[std::size_t(2 * n)] = -delta / beamCosine;
  q[std::size_t(2 * n)] = delta * 0.5 * albedo / beamCosine;
  Matrix sum(m), term(m);
  for (int i = 0; i < m; ++i) sum(i, i) = term(i, i) = 1.0;
  for (int order = 1; order < 100; ++order) {
    double largest = 0.0;
    for (int i = 0; i < m; ++i) {
      double* row = &term.a[std::size_t(i) * std::size_t(m)];
      double* out = &sum.a[std::size_t(i) * std::size_t(m)];
      double rowP = 0.0;
      for (int j = 0; j < m; ++j) rowP += row[j] * p[std::size_t(j)];
      for (int j = 0; j < m; ++j) {
        row[j] = (row[j] * lambda[std::size_t(j)] + rowP * q[std::size_t(j)]) / order;
        out[j] += row[j];
        largest = std::max(largest, std::abs(row[j]));
      }
    }
    if (largest < 1e-18) break;
  }
  Matrix m22(n), rhs(n);
  std::vector<double> beam(mu.size());
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      m22(i, j) = sum(n + i, n + j);
      rhs(i, j) = -sum(n + i, j);
    }
    beam[std::size_t(i)] = -sum(n + i, 2 * n);
  }
  const Lu lu(m22);
  lu.solve(rhs);
  lu.solve(beam);
  r = rhs;
  r0 = beam;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      double v = sum(i, j);
      for (int l = 0; l < n; ++l) v += sum(i, n + l) * r(l, j);
      t(i, j) = v;
    }
    double v = sum(i, 2 * n);
    for (int l = 0; l < n; ++l) v += sum(i, n + l) * r0[std::size_t(l)];
    t0[std::size_t(i)] = v;
  }
}

/// Puts two copies of a layer (r, t: its diffuse matrices; r0, t0: the beam's diffusely
/// reflected and transmitted columns; direct: the beam's unscattered fraction) one on the
/// other, in place. Between them the downward power d and the upward power u satisfy
/// d = (from above) + R u and u = R d + (from below), hence (I - R R)^-1. The beam: the
/// upper copy passes `direct` of it unscattered and t0 scattered downward; the lower copy
/// reflects the unscattered part as direct * r0.
void doubleLayer(Matrix& r, Matrix& t, std::vector<double>& r0, std::vector<double>& t0, double& direct) {
  const int n = r.n;
  Matrix a(n), x(n), tr(n), next(n);
  multiply(r, r, a);
  for (double& v : a.a) v = -v;
  for (int i = 0; i < n; ++i) a(i, i) += 1.0;
  const Lu lu(a);
  std::vector<double> d = multiply(r, r0);
  for (int i = 0; i < n; ++i) d[std::size_t(i)] = t0[std::size_t(i)] + direct * d[std::size_t(i)];
  lu.solve(d);
  std::vector<double> u = multiply(r, d);
  for (int i = 0; i < n; ++i) u[std::size_t(i)] += direct * r0[std::size_t(i)];
  const std::vector<double> reflectedBack = multiply(t, u), passedDown = multiply(t, d);
  for (int i = 0; i < n; ++i) {
    r0[std::size_t(i)] += reflectedBack[std::size_t(i)];
    t0[std::size_t(i)] = passedDown[std::size_t(i)] + direct * t0[std::size_t(i)];
  }
  direct *= direct;

  x = t;
  lu.solve(x);  // (I - R R)^-1 T
  multiply(t, r, tr);
  multiply(tr, x, next);
  for (std::size_t k = 0; k < r.a.size(); ++k) r.a[k] += next.a[k];
  multiply(t, x, next);
  std::swap(t.a, next.a);
}

/// The starting layer's thickness: `from` halved until δ/μ stays under 1/2 for every
/// node and the beam, where its transfer matrix exp(δK) (see thinLayer) is well
/// conditioned and its Taylor series converges in ~20 terms. `halvings` counts them, so
/// that doubling the layer as often gives back `from` exactly.
double startingThickness(double from, const std::vector<double>& mu, double mu0, int& halvings) {
  const double muMin = std::min(mu0, *std::min_element(mu.begin(), mu.end()));
  double delta = from;
  halvings = 0;
  while (delta > 0.5 * muMin) {
    delta *= 0.5;
    ++halvings;
  }
  return delta;
}

/// The arguments both solvers share: albedo in [0, 1], a positive finite eta, at least 2
/// nodes, and a beam cosine that some beam from outside refracts to.
void checkArguments(const char* caller, double albedo, double eta, const AddingDoublingOptions& options) {
  const std::string name(caller);
  if (!(albedo >= 0.0 && albedo <= 1.0)) throw std::invalid_argument(name + ": albedo must be in [0, 1]");
  if (!(eta > 0.0) || !std::isfinite(eta)) throw std::invalid_argument(name + ": eta must be positive");
  if (options.nodes < 2) throw std::invalid_argument(name + ": need at least 2 nodes");
  const double mu0 = options.beamCosine;
  if (!(mu0 > 0.0 && mu0 <= 1.0) || !(eta * eta * (1.0 - mu0 * mu0) < 1.0))
    throw std::invalid_argument(name + ": no beam from outside refracts to that beam cosine");
}

}  // namespace

HalfSpaceReflectance addingDoublingHalfSpace(double albedo, double eta, const AddingDoublingOptions& options) {
  checkArguments("addingDoublingHalfSpace", albedo, eta, options);
  if (!(options.transmittanceTolerance > 0.0) || !(options.maxThickness > 0.0))
    throw std::invalid_argument("addingDoublingHalfSpace: tolerance and thickness must be positive");
  const double mu0 = options.beamCosine;
  const double sin2Outside = eta * eta * (1.0 - mu0 * mu0);

  HalfSpaceReflectance result;
  boundaryQuadrature(options.nodes, eta, result.mu, result.weight);
  const int n = int(result.mu.size());
  const std::vector<double>& mu = result.mu;
  const std::vector<double>& w = result.weight;

  int halvings = 0;
  const double delta = startingThickness(1.0, mu, mu0, halvings);
  const std::size_t bins = mu.size();
  Matrix r(n), t(n);
  std::vector<double> r0(bins), t0(bins);
  thinLayer(albedo, mu, w, mu0, delta, r, t, r0, t0);
  double direct = std::exp(-delta / mu0);  // the beam's unscattered fraction

  double thickness = delta;
  double transmittance = 1.0;
  while (true) {
    doubleLayer(r, t, r0, t0, direct);
    thickness *= 2.0;
    ++result.doublings;

    transmittance = direct;
    for (double v : t0) transmittance += v;
    for (int j = 0; j < n; ++j) {
      double column = 0.0;
      for (int i = 0; i < n; ++i) column += t(i, j);
      transmittance = std::max(transmittance, column);
    }
    if (transmittance < options.transmittanceTolerance || thickness >= options.maxThickness) break;
  }
  result.thickness = thickness;
  result.transmittance = transmittance;

  // The boundary: upward power u reaching it is F u reflected back into the same bins,
  // which the half-space reflects again: u = (1 - F(θi)) r0 + R F u.
  std::vector<double> fresnel(bins);
  for (int i = 0; i < n; ++i) fresnel[std::size_t(i)] = internalFresnel(mu[std::size_t(i)], eta);
  Matrix a(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = (i == j ? 1.0 : 0.0) - r(i, j) * fresnel[std::size_t(j)];
  std::vector<double> u = r0;
  const double entering = 1.0 - fresnelReflectance(std::sqrt(1.0 - sin2Outside), eta);
  for (double& v : u) v *= entering;
  Lu(a).solve(u);
  result.upward = u;
  result.exitFlux.resize(bins);
  for (int i = 0; i < n; ++i) {
    result.exitFlux[std::size_t(i)] = (1.0 - fresnel[std::size_t(i)]) * u[std::size_t(i)];
    result.rd += result.exitFlux[std::size_t(i)];
  }
  return result;
}

SlabTransport addingDoublingSlab(double albedo, double eta, double thickness, const AddingDoublingOptions& options) {
  checkArguments("addingDoublingSlab", albedo, eta, options);
  if (!(thickness > 0.0) || !std::isfinite(thickness))
    throw std::invalid_argument("addingDoublingSlab: thickness must be positive");
  const double mu0 = options.beamCosine;
  const double sin2Outside = eta * eta * (1.0 - mu0 * mu0);
  std::vector<double> mu, w;
  boundaryQuadrature(options.nodes, eta, mu, w);
  const int n = int(mu.size());
  const std::size_t bins = mu.size();
  int doublings = 0;
  const double delta = startingThickness(thickness, mu, mu0, doublings);
  Matrix r(n), t(n);
  std::vector<double> r0(bins), t0(bins);
  thinLayer(albedo, mu, w, mu0, delta, r, t, r0, t0);
  double direct = std::exp(-delta / mu0);
  for (int k = 0; k < doublings; ++k) doubleLayer(r, t, r0, t0, direct);

  // Both faces reflect F(μ) of what reaches them from inside back into the same bin. With u
  // the upward power arriving at the top face and d the downward power at the bottom one:
  //   u = e r0 + R F u + T F d,   d = e t0 + T F u + R F d,   e = 1 - F(θi) entering.
  // The beam's unscattered remainder reaches the bottom face, which reflects F(μ0) of it
  // back up as a beam; by the slab's symmetry that beam sends t0 of itself up and r0 down.
  // What of it crosses the whole slab again unscattered is dropped (e^-2 thickness).
  std::vector<double> fresnel(bins);
  for (int i = 0; i < n; ++i) fresnel[std::size_t(i)] = internalFresnel(mu[std::size_t(i)], eta);
  const double entering = 1.0 - fresnelReflectance(std::sqrt(1.0 - sin2Outside), eta);
  const double backBeam = internalFresnel(mu0, eta) * direct;  // per unit entering power
  Matrix system(2 * n);
  std::vector<double> rhs(std::size_t(2 * n));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double fj = fresnel[std::size_t(j)];
      system(i, j) = (i == j ? 1.0 : 0.0) - r(i, j) * fj;
      system(i, n + j) = -t(i, j) * fj;
      system(n + i, j) = -t(i, j) * fj;
      system(n + i, n + j) = (i == j ? 1.0 : 0.0) - r(i, j) * fj;
    }
    rhs[std::size_t(i)] = entering * (r0[std::size_t(i)] + backBeam * t0[std::size_t(i)]);
    rhs[std::size_t(n + i)] = entering * (t0[std::size_t(i)] + backBeam * r0[std::size_t(i)]);
  }
  Lu(system).solve(rhs);
  SlabTransport result;
  result.transmittedFlux.resize(bins);
  for (int i = 0; i < n; ++i) {
    result.rd += (1.0 - fresnel[std::size_t(i)]) * rhs[std::size_t(i)];
    result.transmittedFlux[std::size_t(i)] = (1.0 - fresnel[std::size_t(i)]) * rhs[std::size_t(n + i)];
    result.td += result.transmittedFlux[std::size_t(i)];
  }
  result.mu = std::move(mu);
  result.weight = std::move(w);
  result.direct = entering * direct * (1.0 - internalFresnel(mu0, eta));
  return result;
}

namespace {

/// The internal Fresnel moments of a smooth boundary: ∫ 2μ (1 - F) dμ (the share of an
/// isotropic field inside that crosses) and ∫ 2μ F dμ, ∫ 3μ² F dμ (2 C1 and 3 C2), on the
/// boundary quadrature (split at the critical cosine, where F has a kink).
struct FresnelMoments {
  double transmitted = 0.0, twoC1 = 0.0, threeC2 = 0.0;
};

FresnelMoments fresnelMoments(double eta, const char* caller) {
  if (!(eta > 0.0) || !std::isfinite(eta)) throw std::invalid_argument(std::string(caller) + ": eta must be positive");
  std::vector<double> mu, w;
  boundaryQuadrature(64, eta, mu, w);
  FresnelMoments m;
  for (std::size_t i = 0; i < mu.size(); ++i) {
    const double reflected = internalFresnel(mu[i], eta);
    m.transmitted += 2.0 * w[i] * mu[i] * (1.0 - reflected);
    m.twoC1 += 2.0 * w[i] * mu[i] * reflected;
    m.threeC2 += 3.0 * w[i] * mu[i] * mu[i] * reflected;
  }
  return m;
}

}  // namespace

double diffuseBoundaryTransmittance(double eta) {
  return fresnelMoments(eta, "diffuseBoundaryTransmittance").transmitted;
}

double diffusionBoundaryCoefficient(double eta) {
  const FresnelMoments m = fresnelMoments(eta, "diffusionBoundaryCoefficient");
  return (1.0 + m.threeC2) / (1.0 - m.twoC1);
}

}  // namespace sslpv

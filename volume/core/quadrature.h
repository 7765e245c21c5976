#pragma once
// Gauss–Legendre quadrature on [0, 1], shared by the closed-form references of the
// calibration: Chandrasekhar's H-function (slab_reflectance.cpp) and the adding-doubling
// direction bins (adding_doubling.cpp).
#include <vector>

namespace sslpv {

/// Nodes x and weights w of an n-point rule: sum_i w[i] f(x[i]) ≈ ∫0^1 f(x) dx, exact for
/// polynomials of degree < 2n. Nodes ascend (x[0] is the smallest).
struct Quadrature {
  std::vector<double> x, w;
};

/// The n-point Gauss–Legendre rule mapped to [0, 1] (n >= 1): Newton on P_n from the
/// guesses cos(π (i + 3/4) / (n + 1/2)), until a step is below 1e-16 (at most 100 a node).
Quadrature gaussLegendreUnit(int n);

}  // namespace sslpv

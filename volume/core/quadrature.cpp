#include "volume/core/quadrature.h"

#include <cmath>
#include <cstddef>
#include "volume/core/math_constants.h"

namespace sslpv {

Quadrature gaussLegendreUnit(int n) {
  Quadrature q;
  q.x.resize(std::size_t(n));
  q.w.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / derivative;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    q.x[std::size_t(i)] = 0.5 * (1.0 - z);
    // 2 / ((1 - z²) P_n'(z)²) on [-1, 1], halved by the map to [0, 1].
    q.w[std::size_t(i)] = 1.0 / ((1.0 - z * z) * derivative * derivative);
  }
  return q;
}

}  // namespace sslpv

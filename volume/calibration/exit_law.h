#pragma once
// The angular shape of the light a thick medium sends out through its boundary, for the
// calibrated SSLPV shading: outside radiance = T(μo)/η² · h(μo; α', η) · L_in, h the
// adding-doubling half-space's radiance just below the boundary (less its once-scattered
// part, which the shading adds itself), normalised so every cell's exitant power equals
// the Lambertian law's (h = 1), which keeps the exit gain's calibration unchanged.
// Table: h at μo = j / SSLPV_EXIT_LAW_MU_INTERVALS and t = sqrt(1 - α') =
// k / SSLPV_EXIT_LAW_ALBEDO_INTERVALS (device_shared/lpv_constants.h), bilinear, each row
// rescaled so the normalisation holds for the interpolant itself; shaders/shade.comp reads
// the same floats the same way. Why and how: docs/design.md §6.7.6 "Exit shape".
#include <vector>

namespace sslpv {

struct ExitLawTable {
  double ior = 1.0;
  /// (SSLPV_EXIT_LAW_ALBEDO_INTERVALS + 1) rows of (SSLPV_EXIT_LAW_MU_INTERVALS + 1) h values.
  std::vector<float> shape;
  double buildMs = 0.0;  ///< wall time of buildExitLawTable
};

/// Builds the table for relative index `ior` (33 adding-doubling solutions).
/// Throws std::invalid_argument unless ior is positive and finite.
ExitLawTable buildExitLawTable(double ior);

/// buildExitLawTable(ior), built on first use for each ior and kept for the process
/// (thread-safe, like boundaryReflectance's table).
const ExitLawTable& exitLawTable(double ior);

/// h(μo; α') from the table, bilinear, in float exactly as shaders/shade.comp computes it.
/// α' is clamped to [0, 1], cosOut to [0, 1].
float exitLawShape(const ExitLawTable& table, float reducedAlbedo, float cosOut);

/// exitLawShape in two halves, for shading that reads many cells for one direction: the
/// table row coordinate of an albedo (one square root, computed once per cell) and the
/// column of a direction (once per pixel). exitLawShapeAt(table, exitLawRow(a),
/// exitLawColumn(c)) is bit-identical to exitLawShape(table, a, c).
struct ExitLawColumn {
  int index = 0;
  float fraction = 0.0f;
};
float exitLawRow(float reducedAlbedo);
ExitLawColumn exitLawColumn(float cosOut);
float exitLawShapeAt(const ExitLawTable& table, float row, ExitLawColumn column);

/// The whole factor the shading applies to a cell's Lambertian radiance inside:
/// (1 - F(cosOut)) / η² · exitLawShape (without the table: the old law, h = 1).
double exitRadianceFactor(const ExitLawTable& table, double reducedAlbedo, double cosOut);

/// The untabulated shape at one α': the adding-doubling radiance interpolated in direction
/// only and normalised with the continuous integral above (for the tests: off-table
/// points; `nodes` as AddingDoublingOptions::nodes). One adding-doubling solution when
/// constructed (~1 ms), then cheap to evaluate.
class ExactExitShape {
 public:
  ExactExitShape(double reducedAlbedo, double ior, int nodes = 32);
  /// h(cosOut), cosOut clamped to [0, 1].
  double operator()(double cosOut) const;

 private:
  double radiance(double cosOut) const;  ///< unnormalised
  double variable(double mu) const;      ///< the interpolation variable of an inside cosine

  double eta_, muC_ = 0.0, scale_ = 1.0;
  std::vector<double> x_, y_, w_;  ///< nodes, radiances, barycentric weights
};

}  // namespace sslpv

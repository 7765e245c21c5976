#pragma once
// The angular shape of the light a thick medium sends out through its boundary, for the
// calibrated SSLPV shading (issue 4, lpv_calibration.h item 4).
//
// Why: the calibrated exit gain makes the power a thick slab reflects exact, but the
// lattice's light leaves as a Lambertian field inside the boundary, L_o = T(μo)/η² · L_in.
// The medium's does not: at low reduced albedo α' it is close to single scattering,
// radiance ∝ 1/(1 + μ) at η = 1 (Chandrasekhar: ∝ H(μ)/(1 + μ) for any α' under normal
// incidence), so a Lambertian exit is too bright near the normal (+11 % for ketchup blue
// at η = 1.3, +24 % at η = 1, view 10° off the normal).
//
// The law: outside radiance = T(μo)/η² · h(μo; α', η) · L_in, with h the radiance of the
// adding-doubling half-space (normal incidence) just below the boundary along the
// direction that refracts into μo, less its once-scattered part α'(1 − F(0))/(4π(1 + μ))
// (the shading adds that light itself, volume/single_scattering.h), normalised so that
//    2 ∫0^1 T(μo)/η² h(μo) μo dμo = 2 ∫0^1 T(μo)/η² μo dμo = diffuseBoundaryTransmittance(η):
// the total exitant power of every cell is exactly what the Lambertian law gave, so the
// exit gain (calibrated against that power) and its tests hold unchanged. h = 1 is the
// old law. Keeping T(μo) outside the table leaves h smooth (the Fresnel kink at the
// critical angle is not tabulated).
//
// Table: h at μo = j / SSLPV_EXIT_LAW_MU_INTERVALS and t = sqrt(1 - α') =
// k / SSLPV_EXIT_LAW_ALBEDO_INTERVALS (volume/lpv_constants.h), bilinear; the node values
// come from the adding-doubling bins interpolated by a polynomial through the escaping
// nodes (barycentric; in s, μ = μc + (1 - μc)s², for η > 1), and each row is scaled so the
// integral above holds for the bilinear interpolant itself. The GPU shading
// (shaders/shade.comp) reads the same floats and interpolates the same way.
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

#pragma once
// Diffuse reflectance of a semi-infinite (or finite), isotropically scattering medium
// behind a smooth dielectric boundary, by the adding-doubling method (van de Hulst,
// Multiple Light Scattering, 1980; Prahl, "The adding-doubling method", in
// Optical-Thermal Response of Laser-Irradiated Tissue, 1995): exact transport for any
// albedo up to a quadrature error the tests show converging. It is the calibrated
// scheme's boundary target. Gauss–Legendre bins in μ inside, light tracked as power per
// bin (energy bookkeeping is a column sum), a thin starting layer from the
// discrete-ordinate equations' exponential, doubled until the slab transmits a negligible
// fraction; the Fresnel boundary is a last added layer, with the bins split at the
// critical cosine for η > 1. Method in full: docs/design.md §6.10 "Adding-doubling".
#include <vector>

namespace sslpv {

struct AddingDoublingOptions {
  /// Quadrature nodes over the hemisphere of direction cosines inside the medium; for
  /// η > 1 half of them lie below the critical cosine (totally reflected), half above.
  int nodes = 16;
  /// Doubling stops once the slab transmits less than this fraction of the power of any
  /// incident bin (and of the normal beam): light a deeper medium could send back is less.
  double transmittanceTolerance = 1e-12;
  /// ... or once it is this many mean free paths thick (reached only near albedo 1, where
  /// transmittance falls off as 1/thickness; `transmittance` then reports what is left).
  double maxThickness = 1048576.0;  // 2^20
  /// Direction cosine, inside the medium, of the collimated beam after refraction: 1 is
  /// normal incidence. Light arriving outside at cos θi refracts to
  /// sqrt(1 - (1 - cos² θi) / η²), so for η > 1 it lies in [sqrt(1 - 1/η²), 1].
  double beamCosine = 1.0;
};

struct HalfSpaceReflectance {
  /// Diffusely reflected power per unit incident power of the collimated beam
  /// (AddingDoublingOptions::beamCosine; normal incidence by default): the entry loss
  /// 1 - F(θi) is included, the specular reflection F(θi) is not.
  double rd = 0.0;
  double thickness = 0.0;      ///< optical thickness of the slab standing in for the half-space
  double transmittance = 0.0;  ///< largest fraction of a bin's power that slab transmits
  int doublings = 0;
  std::vector<double> mu;      ///< quadrature nodes: direction cosines inside the medium
  std::vector<double> weight;  ///< their weights, summing to 1 over [0, 1]
  /// Power leaving through the boundary from each node's bin, per unit incident power
  /// (sums to rd). Exitant radiance outside along the refracted direction of node i:
  /// π L / E = exitFlux[i] / (2 weight[i] mu[i] η²).
  std::vector<double> exitFlux;
  /// Power arriving at the boundary from inside in each node's bin, per unit incident
  /// power, before the boundary splits it (exitFlux = (1 - F) upward). The radiance just
  /// below the boundary along node i is proportional to upward[i] / (weight[i] mu[i]):
  /// the medium's exit angular shape (volume/calibration/exit_law.h).
  std::vector<double> upward;
};

/// Rd of a semi-infinite medium with single-scattering albedo `albedo` in [0, 1] and
/// isotropic scattering (use the reduced albedo α' for anisotropic media: similarity
/// relation), boundary of relative index `eta` = n_inside / n_outside > 0, lit by a
/// collimated beam (along the normal unless options.beamCosine says otherwise). Deterministic; about 0.25 ms with the default
/// options (16 nodes: within 1e-8 of the converged value, see adding_doubling_test).
/// Throws std::invalid_argument for an albedo outside [0, 1], a non-positive or non-finite
/// eta, fewer than 2 nodes, a non-positive tolerance or thickness, or a beam cosine outside
/// (0, 1] that no beam from outside refracts into.
HalfSpaceReflectance addingDoublingHalfSpace(double albedo, double eta, const AddingDoublingOptions& options = {});

struct SlabTransport {
  double rd = 0.0;      ///< diffusely reflected power per unit incident power (entry loss included)
  double td = 0.0;      ///< diffusely transmitted power through the far face, per unit incident power
  double direct = 0.0;  ///< the beam's unscattered power leaving through the far face, per unit incident power
  std::vector<double> mu;      ///< quadrature nodes: direction cosines inside the medium
  std::vector<double> weight;  ///< their weights, summing to 1 over [0, 1]
  /// Diffuse power leaving through the far face from each node's bin, per unit incident
  /// power (sums to td); the radiance outside along node i's refracted direction is
  /// π L / E = transmittedFlux[i] / (2 weight[i] mu[i] η²), as for HalfSpaceReflectance.
  std::vector<double> transmittedFlux;
};

/// A slab of optical thickness `thickness` (mean free paths, σt = 1) of the same medium as
/// addingDoublingHalfSpace, with the same smooth boundary on both faces, lit by the beam on
/// one face: what it reflects and what it transmits diffusely. The slab is thickness / 2^k
/// doubled k times, so any thickness is exact; the beam the far face reflects back is
/// followed until it scatters (what of it crosses the slab twice unscattered, a share
/// e^-2thickness, is dropped). Throws std::invalid_argument like
/// addingDoublingHalfSpace, and for a non-positive or non-finite thickness.
SlabTransport addingDoublingSlab(double albedo, double eta, double thickness, const AddingDoublingOptions& options = {});

/// Fraction of the power of a Lambertian (uniform-radiance) field inside a medium of
/// relative index `eta` that crosses its smooth boundary: 1 minus the internal diffuse
/// Fresnel reflectance, total internal reflection included; = (1 - F̄_outside) / η².
double diffuseBoundaryTransmittance(double eta);

/// The diffusion boundary coefficient A = (1 + 3 C2) / (1 - 2 C1) of a smooth boundary of
/// relative index `eta`, from the internal Fresnel moments 2 C1 = ∫ 2μ F dμ and
/// 3 C2 = ∫ 3μ² F dμ (d'Eon and Irving 2011): the diffuse field's extrapolation length is
/// 2 A D. 1 at eta = 1. Throws std::invalid_argument unless eta is positive and finite.
double diffusionBoundaryCoefficient(double eta);

}  // namespace sslpv

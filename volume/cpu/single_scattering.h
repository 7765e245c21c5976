#pragma once
// The calibrated shading's single-scattering term: light that scatters exactly once
// between entering the object and leaving it toward the camera, evaluated per pixel
// instead of carried by the lattice (whose coupling gain targets the rest, Rd − Rd₁).
// With the similarity relation's isotropic medium, along the refracted view ray t from p:
// L(p, −t) = ∫ σs'/(4π) Σ_lights E_l exp(−σt' P_l(p + s t)) exp(−σt' s) ds, E_l the light's
// refracted irradiance and P_l Jensen et al.'s (2001) planar refracted path from its entry,
// both from the shadow-map texel that sees the point half a cell inside p. P_l is linear
// below a planar entry face, so the integral has a closed form; the camera sees T(θo)/η²
// of it. Derivation, the cut past a terminator and what the closed form gives up:
// docs/design.md §6.8 "Single scattering" and §6.7.8.
#include <array>
#include <cstddef>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

#include "volume/lpv/lpv_grid.h"
#include "volume/scene/shadow_view.h"

namespace sslpv {

/// What the single-scattering term reads of one shadow-map texel.
struct EntryTexel {
  glm::vec3 position{0.0f};   ///< where the texel's ray meets the surface
  float pathScale = 0.0f;     ///< cos θi / cos θt: refracted path per straight distance below the surface
  glm::vec3 irradiance{0.0f}; ///< E T(θi) cos θi / cos θt per channel; 0 for a miss or no light
  float distance = 0.0f;      ///< of the hit along the texel ray (orthographic: from its start plane)
  glm::vec3 direction{0.0f};  ///< unit refracted direction of the light inside
  /// ∇P, the gradient of the refracted path below the entry face: −n / cos θt (n the
  /// face's outward normal), so that P(q) = max(0, below) · pathScale is linear across it.
  glm::vec3 pathGradient{0.0f};
};

/// Every texel of one shadow-map view, row by row as ShadowView orders them.
struct EntryMap {
  ShadowView view;
  int light = 0;  ///< index of the view's light (a cube map has six views of one light)
  std::vector<EntryTexel> texels;
};

/// ∫_0^S exp(−σ s − σ max(0, p0 + k s)) ds: the once-scattered light along a refracted view
/// ray in a medium of reduced extinction σ, where the light's refracted path from its entry
/// is p0 + k s at distance s along the ray (k = ∇P · t; past P = 0 the light leg is
/// empty). The ray leaves the object at `end`; where that is ∞ (not within reach) and P
/// falls (k < 0, light from behind), it ends where P = 0, where that light entered.
double singleScatteringIntegral(double sigma, double p0, double k,
                                double end = std::numeric_limits<double>::infinity());

/// Where the view ray from surface point p along `into` leaves the object: the middle of
/// the first cell step whose cell is not active, searched for SSLPV_SINGLE_SCATTERING_EXIT_DEPTH
/// optical depths of `extinction` (at most the grid's longest side); ∞ when it does not
/// leave within them. Within half a cell of the true exit.
double viewRayExit(const MaterialGrid& material, const glm::dvec3& p, const glm::dvec3& into, double extinction);

/// What the term reads of the grid's occupancy at one surface point, which only the
/// geometry (mesh, grid, camera) decides: a renderer keeps it while lights and strokes
/// change the rest.
struct SingleScatteringGeometry {
  /// The medium's trilinear cells and weights half a cell inside p (`used` 0: none).
  std::array<std::size_t, 8> cells{};
  std::array<float, 8> weights{};
  int used = 0;
  /// The first whole-cell step along `into` whose cell is not active among the first
  /// `exitSearched` (0: none there; viewRayExit searches on where the medium is clear).
  int exitStep = 0;
  int exitSearched = 0;
};
SingleScatteringGeometry singleScatteringGeometry(const MaterialGrid& material, const glm::dvec3& p,
                                                  const glm::dvec3& inward, const glm::dvec3& into);

/// L(p, −t) above, per channel, inside the boundary: `into` is the refracted view
/// direction (unit, into the medium), `inward` the inward unit normal at p. The medium and
/// each light's entry are read half a cell inside p (where the shading's exit law reads
/// the lattice); the view leg is singleScatteringIntegral with P and its gradient from the
/// entry texel: exact for a homogeneous half-space under a distant light, and for a slab
/// lit from behind.
glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into);
/// The same with the point's geometry already known (bit for bit the same result).
glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into,
                                  const SingleScatteringGeometry& geometry);

}  // namespace sslpv

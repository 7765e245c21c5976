#pragma once
// The calibrated shading's single-scattering term: light that scatters exactly once
// between entering the object and leaving it toward the camera, integrated per pixel
// along the refracted view ray instead of carried by the lattice (whose coupling gain
// targets the rest, Rd − Rd₁). With the similarity relation's isotropic medium:
// L(p, −t) = ∫ σs'(q)/(4π) Σ_lights E_in(q) exp(−σt'(q) s'_l(q)) exp(−τ(p, q)) ds, q = p + s t,
// E_in the light's refracted irradiance from its shadow map's texel through q, s'_l
// Jensen et al.'s (2001) planar refracted path, samples at midpoints in
// u = 1 − exp(−σt'(p) s); the camera sees T(θo) / η² of it. Radiance in scene units as
// the renderer's. Why, and the rejection past a terminator: docs/design.md §6.8
// "Single scattering" and §6.7.8.
#include <glm/vec3.hpp>
#include <vector>

#include "volume/lpv_grid.h"
#include "volume/shadow_view.h"

namespace sslpv {

/// What the single-scattering term reads of one shadow-map texel.
struct EntryTexel {
  glm::vec3 position{0.0f};   ///< where the texel's ray meets the surface
  float pathScale = 0.0f;     ///< cos θi / cos θt: refracted path per straight distance below the surface
  glm::vec3 irradiance{0.0f}; ///< E T(θi) cos θi / cos θt per channel; 0 for a miss or no light
  float distance = 0.0f;      ///< of the hit along the texel ray (orthographic: from its start plane)
  glm::vec3 direction{0.0f};  ///< unit refracted direction of the light inside
};

/// Every texel of one shadow-map view, row by row as ShadowView orders them.
struct EntryMap {
  ShadowView view;
  int light = 0;  ///< index of the view's light (a cube map has six views of one light)
  std::vector<EntryTexel> texels;
};

/// Groups the channels by σt' (`extinction` at the surface; a new group wherever one
/// exceeds SSLPV_SINGLE_SCATTERING_GROUP_SPREAD times its group's smallest): group[ch] is the channel's
/// group (−1 where σt' is 0), reference[g] the σt' the group's samples are spaced for,
/// the geometric mean of its smallest and largest. Returns the number of groups (0-3).
/// Sharing costs accuracy only in the view leg, e^{(σ_ref − σt') s}: (1 − u)^{σt'/σ_ref − 1}
/// in the sample variable, which 8 midpoints integrate within 1.5 % across a group.
int singleScatteringGroups(const glm::dvec3& extinction, int group[3], double reference[3]);

/// L(p, −t) above, per channel, inside the boundary: `into` is the refracted view
/// direction (unit, into the medium), `inward` the inward unit normal at p. `reach`, when
/// given, receives the farthest sample distance along `into` that was looked up.
glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into,
                                  double* reach = nullptr);

/// Whether singleScatteredRadiance at (p, inward, into) with that `reach` can read a cell
/// of `cells`: its surface lookup or a sample point along [p, p + reach·into] has one
/// among its trilinear corners. Conservative: true may be a miss, false never is.
bool singleScatteringReads(const GridFrame& frame, const glm::dvec3& p, const glm::dvec3& inward,
                           const glm::dvec3& into, double reach, const CellRange& cells);

/// The term of every pixel of the last frame, for shadeImage. Why: the term is most of a
/// frame's shading, and a brush stroke changes the medium of a few cells, so re-shading
/// after a stroke integrates again only the pixels whose samples read them. It holds for
/// one camera, one set of shadow maps and one grid frame; whoever changes those clears it.
struct SingleScatteringCache {
  bool valid = false;
  std::vector<glm::vec3> term;  ///< per pixel, the radiance the term adds (outside)
  std::vector<float> reach;     ///< per pixel, singleScatteredRadiance's reach
};

}  // namespace sslpv

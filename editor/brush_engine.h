#pragma once
// The brush engine: paints σt, σs and g into a material set's OpenVDB grids (docs/design.md
// §4), with an unbounded, exact undo/redo history. Headless (no VTK, no
// Vulkan): `sslpv paint` and the editor drive the same code.
//
// Space. Painting happens in the object's rest space, which is the grids' space. Stroke
// points, rays, the radius and the depth are given in world space; points map through the
// inverse of the scene transform (a similarity: radius_rest = radius / scale). Voxel
// (i,j,k) sits at the grid transform's indexToWorld(i,j,k) (OpenVDB's cell-centred
// convention; the grid's "world" is the rest space).
//
// Material of a voxel. A voxel inactive in a grid takes the base material for that grid
// (docs/design.md §4). When the brush writes a voxel it makes its whole material explicit: the
// voxel becomes active in all three grids (σt, σs, g), unless the result equals the base
// material exactly in all three, in which case it becomes inactive in all three (value set
// to each grid's background). So erasing restores the base, and smoothing an unpainted
// region activates nothing. A missing g grid is created (background = base g).
//
// One dab at rest-space centre c, per voxel v at rest position p within the radius:
//   u = |p - c| / radius_rest                       (u > 1: the voxel is not touched)
//   w = falloff(u):
//     constant  w = 1
//     linear    w = 1 - u
//     smooth    w = 1 - u²(3 - 2u)                   (1 - smoothstep(0, 1, u))
//     gaussian  w = (exp(-4.5 u²) - exp(-4.5)) / (1 - exp(-4.5))
//                                                    (σ = radius/3, shifted to reach 0 at u = 1)
//   t = w · strength                                 (t <= 0: the voxel is not touched)
// and every channel x the brush drives (read as the voxel's current material) becomes
//   set       x' = x + t (target - x)
//   add       x' = x + t · value
//   multiply  x' = x · (1 + t (value - 1))
//   smooth    x' = x + t (avg - x),   avg = mean of the 3x3x3 neighbourhood, read before the dab
//   erase     x' = x + t (base - x)
// with x' = target / avg / base exactly when t = 1 (set, smooth, erase). Arithmetic is in
// double; the result is stored as float.
//
// Channels: sigma_t (σt, RGB), sigma_s (σs, RGB), g; Colour (the artist's form: surface
// colour, scatter distance and g, volume/material/artist_params.h) drives σt, σs and g with the
// targets artistToPhysical gives behind the target's boundary index; albedo_mfp drives σt
// and σs with the targets σt = 1 / mean_free_path, σs = albedo · σt; preset drives σt, σs
// (Jensen 2001, valid with g = 0) and g (target 0); All (smooth, erase only) drives σt, σs
// and g. Colour, albedo_mfp and preset take mode set only; add and multiply need sigma_t,
// sigma_s or g.
// σ values (targets, add values) are per scene unit like the scene's base material and are
// converted to the set's units; radius and depth are world lengths.
//
// Validity (after every voxel write, in this order): σt clamped to [0, FLT_MAX]; σs clamped
// to [0, σt] per channel (σs is clamped, not scaled: painting σt alone changes the albedo,
// albedo_mfp is the control that keeps it); g clamped to [-0.99, 0.99]. Inputs are
// finite, so no NaN or Inf can arise.
//
// Strokes. A stroke is a world-space polyline of points or a list of rays hitting the
// surface. Dabs sit at the points and along each segment at a spacing of at most
// radius / 4 (segment of length L: ceil(4L / radius) equal steps; a point equal to the
// previous one adds none), and are applied one after another (overlapping dabs build up
// like an airbrush's flow). Rays are intersected
// with the object's world mesh; between two consecutive hits the rays are interpolated
// (origins linearly, directions linearly then normalized) and re-intersected, halving up
// to 12 times, until neighbouring hits are at most radius / 4 apart, so the stroke follows
// the surface. A ray that misses ends the current path (no fill across it). With depth
// d > 0 each surface dab becomes a column of dabs from the hit to hit - d·n (n the outward
// normal), at a spacing of at most radius / 4.
//
// Mirror. With a mirror the dab at c and its reflection c' across the rest-space plane
// (axis x|y|z, at = coordinate, default the centre of the object's rest bounds) are applied
// as one dab with w = falloff(min(|p - c|, |p - c'|) / radius_rest). When the grid's index
// axes are the rest axes (any scale + translation) the plane snaps to the nearest multiple
// of half a voxel (see mirrorPlane()) and v's mirror voxel is found by index, so the
// result is exactly symmetric; for rotated grid transforms the reflection is geometric.
//
// History. Each stroke records, for exactly the voxels it wrote, the stored values and
// active states before and after (76 bytes a voxel); undo writes back "before", redo
// "after", so both are bit-identical. Unbounded; memory grows with touched voxels only.
// A new stroke after an undo drops the strokes that could have been redone.
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "volume/material/artist_params.h"
#include "volume/scene/material.h"
#include "volume/material/material_set.h"
#include "volume/scene/mesh.h"
#include "volume/lpv/resample.h"

namespace sslpv {

struct Scene;

enum class BrushChannel { SigmaT, SigmaS, G, AlbedoMfp, Preset, All, Colour };
enum class BrushMode { Set, Add, Multiply, Smooth, Erase };
enum class BrushFalloff { Constant, Linear, Smooth, Gaussian };

/// The falloff weight w(u) above; 0 for u > 1 (and for a NaN u).
double falloffWeight(BrushFalloff falloff, double u);

/// Largest |g| the brush writes.
inline constexpr float kBrushMaxG = 0.99f;

struct BrushMirror {
  int axis = 0;              ///< 0 = x, 1 = y, 2 = z (rest space)
  std::optional<double> at;  ///< rest-space coordinate; default: centre of the rest bounds
};

struct Brush {
  BrushChannel channel = BrushChannel::All;
  BrushMode mode = BrushMode::Set;
  glm::dvec3 rgb{0.0};           ///< sigma_t/sigma_s: set target, add value (per scene unit) or multiply factor
  double scalar = 0.0;           ///< g: set target, add value or multiply factor
  glm::dvec3 albedo{1.0};        ///< albedo_mfp: in [0, 1]
  glm::dvec3 meanFreePath{1.0};  ///< albedo_mfp: > 0, scene units
  std::string preset;            ///< preset: a Jensen 2001 material name
  /// Colour: surface colour, scatter distance (scene units) and g. The colour's upper
  /// bound depends on the target's ior, so the engine checks it, not brushProblem.
  ArtistParams artist;
  double radius = 1.0;           ///< world units, > 0
  BrushFalloff falloff = BrushFalloff::Smooth;
  double strength = 1.0;  ///< [0, 1]
  std::optional<BrushMirror> mirror;
  double depth = 0.0;  ///< ray strokes: paint this far along the inward normal (world units)
};

/// Describes what is wrong with `brush` ("radius: must be positive, got 0"), or "" when
/// it is usable; the prefix is the stroke file's key name.
std::string brushProblem(const Brush& brush);

struct SurfaceRay {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  ///< need not be normalized, must be non-zero
};

struct Stroke {
  Brush brush;
  std::vector<glm::dvec3> points;  ///< world space; or
  std::vector<SurfaceRay> rays;    ///< world space (exactly one of the two is non-empty)
};

/// What a finished stroke (or its undo/redo) changed.
struct StrokeResult {
  /// World-space box around every changed voxel's support (voxel centre ± 1 voxel in index
  /// space, where the trilinear field changes): pass it to resampleMaterialRegion().
  /// Empty when nothing changed.
  Bounds worldBounds;
  std::size_t voxelsChanged = 0;  ///< voxels whose stored value or active state differs
  std::size_t dabs = 0;           ///< dabs applied (a mirrored pair counts once)
  std::size_t raysMissed = 0;     ///< rays (given, not interpolated) that missed the object
};

/// What one incremental call of a stroke in progress wrote (for live preview).
struct DabResult {
  Bounds worldBounds;             ///< support of the voxels written by this call
  std::size_t voxelsWritten = 0;  ///< voxel writes (a voxel written by two dabs counts twice)
  std::size_t dabs = 0;
  std::size_t raysMissed = 0;
};

/// What the engine paints on.
struct PaintTarget {
  /// Painted in place. sigma_t and sigma_s required; all grids must share one linear
  /// transform. g may be missing (created on construction).
  std::shared_ptr<MaterialSet> set;
  MaterialSample base;                            ///< the scene's base material, per scene unit
  double sceneUnitInMm = 1.0;                     ///< converts σ between the scene's and the set's units
  glm::dmat4 restToWorld{1.0};                    ///< the scene transform (similarity)
  Bounds restBounds;                              ///< the object's rest-space bounds (default mirror plane)
  std::shared_ptr<const TriangleMesh> worldMesh;  ///< for ray strokes; may be null
  /// The object's boundary index (the scene's material.ior): what Colour brushes' surface
  /// colour is seen through.
  double ior = 1.0;
};

/// Voxels per side of the longest rest-space extent when a scene has no material set.
inline constexpr double kDefaultVoxelsPerExtent = 128.0;

/// Grids with nothing active: backgrounds = `baseInSetUnits` (σt, σs, g), cell-centred
/// linear transform of `voxelSize` (voxel (0,0,0) centred on the rest-space origin).
std::shared_ptr<MaterialSet> makeEmptyMaterialSet(const MaterialSample& baseInSetUnits, double voxelSize,
                                                  const std::string& units);

/// The scene's object as a paint target: the world mesh (closed-ness checked), the scene's
/// material set (deep copy, painted in its own units) or, without one, empty grids in the
/// scene's units with voxel size = longest rest-space extent / 128. Throws InputError.
PaintTarget makePaintTarget(const Scene& scene);

class BrushEngine {
 public:
  /// Throws InputError when the set is unusable (missing grids, differing or non-linear
  /// transforms, an unknown unit) or restToWorld is not a similarity.
  explicit BrushEngine(PaintTarget target);
  ~BrushEngine();
  BrushEngine(const BrushEngine&) = delete;
  BrushEngine& operator=(const BrushEngine&) = delete;

  /// beginStroke + addPoints/addRays + endStroke: one undo step. When painting throws,
  /// the stroke is ended first, so what it painted before the failure can be undone.
  StrokeResult applyStroke(const Stroke& stroke);

  /// Incremental strokes (an editor's drag): the dabs of each call continue the path of
  /// the previous call. Throws InputError for an unusable brush (brushProblem), a missing
  /// mesh for rays, a dab covering more than 2^26 voxels or a call needing more than 10^6
  /// dabs; painting done so far stays part of the stroke. beginStroke during a stroke
  /// ends that stroke first.
  void beginStroke(const Brush& brush);
  DabResult addPoints(const std::vector<glm::dvec3>& worldPoints);
  DabResult addRays(const std::vector<SurfaceRay>& worldRays);
  /// Records the stroke in the history (even when nothing changed) and returns its totals.
  StrokeResult endStroke();
  bool strokeInProgress() const;

  bool canUndo() const;
  bool canRedo() const;
  /// Restores the voxels of the last stroke; the result is that stroke's (region to resample).
  std::optional<StrokeResult> undo();
  std::optional<StrokeResult> redo();
  std::size_t historyStrokes() const;  ///< strokes that can be undone
  std::size_t historyBytes() const;    ///< memory held by the undo and redo records

  /// The set being painted (same grids, updated in place).
  std::shared_ptr<const MaterialSet> materialSet() const;
  /// The base material in the set's units, as inactive voxels read it.
  const MaterialSample& baseInSetUnits() const;
  /// σ per scene unit times this gives σ per set unit.
  double sigmaToSetUnits() const;
  /// The rest-space coordinate the mirror plane snaps to (see the header comment).
  double mirrorPlane(const BrushMirror& mirror) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sslpv

#pragma once
// The brush engine: paints σt, σs and g into a material set's OpenVDB grids (docs/design.md
// §4), with an unbounded, exact undo/redo history. Headless (no VTK, no
// Vulkan): `sslpv paint` and the editor drive the same code.
// Space, per-voxel material, the dab arithmetic, channels, validity, strokes, mirror and
// history: docs/design.md §4.1.
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

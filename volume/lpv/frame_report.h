#pragma once
// What a backend reports about a frame, and which of its stages must re-run: shared by
// the CPU and Vulkan backends so both print the same table and skip the same work.
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "volume/lpv/lpv_grid.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

enum class Stage : unsigned { Voxelize, Resample, ShadowMap, Injection, Propagation, Shading };

/// Milliseconds of each stage in this frame. A stage whose inputs did not change since
/// the last frame is not run; it is marked cached and costs 0.
struct StageTimes {
  double load = 0, voxelize = 0, resample = 0;
  double shadowMap = 0, injection = 0, propagation = 0, shading = 0;
  unsigned cachedMask = 0;
  double frame() const { return shadowMap + injection + propagation + shading; }
  bool cached(Stage s) const { return cachedMask & (1u << unsigned(s)); }
  void markCached(Stage s) { cachedMask |= 1u << unsigned(s); }
};

/// What the coarse levels of one frame cost.
struct CoarseStartReport {
  int levels = 0;       ///< grids solved below the frame's own (0: no coarse start)
  int steps = 0;        ///< propagation steps on all of them
  double ms = 0.0;      ///< voxelize, resample, inject and propagate on all of them
};

struct RenderReport {
  StageTimes times;
  GridFrame frame;
  std::string backend = "cpu";
  std::size_t activeCells = 0;
  std::size_t triangles = 0;
  std::size_t resampledCells = 0;  ///< cells resampled this frame (0 when cached)
  /// Wall-clock milliseconds of the whole frame as the caller saw it, submissions and
  /// read-backs included (the stage rows of the GPU backend are device times).
  double wallMs = 0.0;
  /// Per light. The Vulkan backend fills texels and culled only (see VulkanRenderer).
  std::vector<ShadowMapStats> lights;
  InjectionStats injection;
  PropagationResult propagation;
  /// The coarse grids that started a cold propagation (CpuRenderer; volume/cpu/coarse_start.h).
  CoarseStartReport coarseStart;
  /// StepFactors::opticalThickness of the last resampling (0: unknown or seed scheme).
  glm::dvec3 opticalThickness{0.0};
};

/// Dirty flags of the frame's stages, following the data flow (docs/design.md §2): each change
/// marks the first stage it affects and everything downstream of it.
class StageDirty {
 public:
  StageDirty() { everything(); }
  void everything() { flags_ = ~0u; region_.reset(); }
  /// The mesh or the grid frame changed: the occupancy and everything after it.
  void geometryChanged() { everything(); }
  /// The material changed inside `region` (world bounds), or everywhere when absent.
  /// Occupancy and the shadow maps depend only on the surface, so they stay; injection
  /// reruns (the calibrated scheme injects at a material-dependent depth).
  void materialChanged(const std::optional<Bounds>& region);
  /// A light moved, changed or was added: shadow maps onwards.
  void lightsChanged() { set({Stage::ShadowMap, Stage::Injection, Stage::Propagation, Stage::Shading}); }
  /// Only the camera moved: shading alone.
  void cameraChanged() { set({Stage::Shading}); }
  /// The shadow-map size or step count changed (a resolution change is geometryChanged).
  void settingsChanged(const LpvSettings& before, const LpvSettings& after);

  bool dirty(Stage s) const { return flags_ & bit(s); }
  /// Region of a partial material change; empty when the whole material must resample.
  const std::optional<Bounds>& resampleRegion() const { return region_; }
  void clear() { flags_ = 0; region_.reset(); }

 private:
  static unsigned bit(Stage s) { return 1u << unsigned(s); }
  void set(std::initializer_list<Stage> stages) {
    for (Stage s : stages) flags_ |= bit(s);
  }
  unsigned flags_ = 0;
  std::optional<Bounds> region_;
};

/// The seed-style timing table (shadow map, injection, propagation, shading, total, ms),
/// followed by the setup stages and the grid that was used.
std::string formatTimings(const RenderReport& report);

}  // namespace sslpv

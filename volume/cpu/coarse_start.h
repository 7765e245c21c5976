#pragma once
// Coarse-to-fine start of a cold calibrated propagation. The semi-iteration's slowest
// modes are the light's large-scale shape, and they slow down as cells shrink (the
// steps --steps auto needs roughly double per halving of the cell: 151 at 32³, 488 at
// 64³ on the frame benchmark's sphere). The same frame solved on a grid of half the
// resolution gets that shape for an eighth of the cost per step and fewer steps; its
// light, prolonged onto the fine grid, starts the fine run, which then only has to
// converge what the coarse grid could not represent. The fine run keeps its own stop
// rule, so the result meets the same tolerance as a cold run (docs/design.md §6.9).
#include <memory>
#include <optional>
#include <vector>

#include "volume/lpv/frame_report.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/mesh.h"

namespace sslpv {

class SceneObject;

/// Where coarse-to-fine stops: a grid of fewer cells along its longest side is solved
/// cold (its propagation costs little next to the frame's other stages).
inline constexpr int kCoarseStartMinResolution = 16;

/// The coarse levels below one renderer's grid, kept between frames: a coarse level is
/// voxelized again only when the mesh or the grid changes, resampled only where the
/// material changed.
class CoarseStart {
 public:
  CoarseStart();
  ~CoarseStart();
  CoarseStart(CoarseStart&&) noexcept;
  CoarseStart& operator=(CoarseStart&&) noexcept;

  /// The mesh or the grid resolution changed: every level is rebuilt.
  void geometryChanged();
  /// The material changed inside `touched` (nullopt: everywhere).
  void materialChanged(const std::optional<Bounds>& touched);

  /// Solves the frame (the object's field, the light `samples` a shadow-map pass cast) on
  /// a grid of half `fine`'s resolution (itself started from a coarser one), with
  /// `options`' stop rule, and fills `warm` with that light on `fine`'s cells. False,
  /// with `warm` untouched, where `fine` is too small to coarsen or the scheme is not one
  /// the semi-iteration runs (calibrated, auto steps).
  bool start(const SceneObject& object, const MaterialGrid& fine, const StepFactors& fineFactors, int resolution,
             double ior, const std::vector<SurfaceFluxSample>& samples, const PropagationOptions& options,
             PropagationWarmStart& warm, CoarseStartReport* report = nullptr);

 private:
  struct Level;
  std::unique_ptr<Level> level_;
};

/// The light of `coarse` (per channel, c0 over coarse.frame's cells) on the active cells
/// of `fine`: trilinear over the coarse grid's active cells at each fine cell's centre,
/// times (fine cell / coarse cell)², since a cell's c0 is an intensity through a face of
/// the cell's size and the radiance it stands for is the same on both grids.
std::array<std::vector<float>, 3> prolongLight(const MaterialGrid& coarse, const std::array<std::vector<float>, 3>& light,
                                               const MaterialGrid& fine, const std::vector<unsigned char>& fineActive);

}  // namespace sslpv

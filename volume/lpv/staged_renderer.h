#pragma once
// The frame skeleton both backends share (docs/design.md §2): which of the six stages a
// frame re-runs, and the report's bookkeeping and timings.
#include <optional>

#include "volume/core/image_io.h"
#include "volume/lpv/frame_report.h"
#include "volume/lpv/renderer.h"

namespace sslpv {

/// A Renderer whose frame runs voxelization, resampling, shadow maps, injection,
/// propagation and shading in that order, each only when its inputs changed since the
/// last frame (dirty_, which the setters mark). A backend implements one hook per stage;
/// a hook returns the stage's milliseconds (the device time on a GPU) and fills the
/// report's fields of that stage. The report is kept between frames, so a cached stage's
/// fields still describe the result the frame uses.
class StagedRenderer : public Renderer {
 public:
  Image render(const LpvSettings& settings, RenderReport* report = nullptr) final;

 protected:
  /// Called before a frame whose settings differ from the last frame's.
  virtual void settingsChanging(const LpvSettings& before, const LpvSettings& after) {
    (void)before;
    (void)after;
  }
  virtual double runVoxelize(const LpvSettings& settings, RenderReport& report) = 0;
  virtual double runResample(const LpvSettings& settings, RenderReport& report) = 0;
  virtual double runShadowMaps(const LpvSettings& settings, RenderReport& report) = 0;
  virtual double runInjection(RenderReport& report) = 0;
  virtual double runPropagation(const LpvSettings& settings, RenderReport& report) = 0;
  virtual double runShading(Image& image) = 0;

  StageDirty dirty_;
  /// Setup time (mesh, material set, pipelines), reported with every frame.
  double loadMs_ = 0.0;
  RenderReport last_;

 private:
  std::optional<LpvSettings> lastSettings_;
  Image image_;
};

}  // namespace sslpv

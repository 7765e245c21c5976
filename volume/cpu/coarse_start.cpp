#include "volume/cpu/coarse_start.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "volume/material/material_set.h"
#include "volume/material/scene_object.h"
#include "volume/lpv/voxelize_parity.h"
#include "volume/lpv/resample.h"
#include "volume/cpu/inject.h"
#include "volume/cpu/propagate.h"

namespace sslpv {

struct CoarseStart::Level {
  int resolution = 0;
  MaterialGrid material;
  StepFactors factors;
  bool voxelized = false, resampled = false;
  std::optional<Bounds> touched;  ///< material changed only here since the last resample
  std::unique_ptr<CoarseStart> coarser;
};

CoarseStart::CoarseStart() = default;
CoarseStart::~CoarseStart() = default;
CoarseStart::CoarseStart(CoarseStart&&) noexcept = default;
CoarseStart& CoarseStart::operator=(CoarseStart&&) noexcept = default;

void CoarseStart::geometryChanged() { level_.reset(); }

void CoarseStart::materialChanged(const std::optional<Bounds>& touched) {
  if (!level_ || !level_->resampled) return;
  if (touched && level_->touched) {
    level_->touched->extend(touched->min);
    level_->touched->extend(touched->max);
  } else {
    level_->touched = touched;
  }
  level_->resampled = touched.has_value();  // a whole-field change resamples everything
  if (level_->coarser) level_->coarser->materialChanged(touched);
}

bool CoarseStart::start(const SceneObject& object, const MaterialGrid& fine, const StepFactors& fineFactors,
                        int resolution, double ior, const std::vector<SurfaceFluxSample>& samples,
                        const PropagationOptions& options, PropagationWarmStart& warm, CoarseStartReport* report) {
  const int coarseResolution = resolution / 2;
  if (coarseResolution < kCoarseStartMinResolution || !options.autoSteps || !options.chebyshev ||
      fineFactors.scheme != LpvScheme::Calibrated || !keepsCellsIsotropic(fineFactors))
    return false;
  const auto began = std::chrono::steady_clock::now();
  if (!level_ || level_->resolution != coarseResolution) {
    level_ = std::make_unique<Level>();
    level_->resolution = coarseResolution;
  }
  Level& level = *level_;
  if (!level.voxelized) {
    level.material = MaterialGrid{};
    level.material.frame = makeGridFrame(object.gridBounds(), coarseResolution);
    level.material.meanChord = fine.meanChord;
    level.material.coverage = voxelizeCoverageParity(object.mesh(), level.material.frame);
    level.voxelized = true;
    level.resampled = false;
    level.touched.reset();
  }
  if (!level.resampled || level.touched) {
    if (level.resampled && level.touched)
      resampleMaterialRegion(object.field(), level.material, *level.touched);
    else
      resampleMaterial(object.field(), level.material);
    level.factors = computeStepFactors(level.material, fineFactors.scheme, ior);
    level.resampled = true;
    level.touched.reset();
  }

  ShGrid field;
  field.resize(level.material.frame);
  injectSamples(samples, level.material, field, &level.factors);
  ShGrid accumulated;
  accumulated.resize(level.material.frame);
  PropagationWarmStart coarseWarm;
  PropagationOptions coarseOptions = options;
  coarseOptions.warmStart = &coarseWarm;
  coarseOptions.recordEnergy = false;
  if (!level.coarser) level.coarser = std::make_unique<CoarseStart>();
  CoarseStartReport below;
  level.coarser->start(object, level.material, level.factors, coarseResolution, ior, samples, options, coarseWarm,
                       &below);
  const PropagationResult result = propagate(level.material, level.factors, field, accumulated, coarseOptions);
  // A dark frame leaves nothing to start from; the fine run finds it dark itself.
  if (!coarseWarm.holds(level.material.frame)) return false;

  warm.clear();
  warm.frame = fine.frame;
  warm.rho = coarseWarm.rho;
  warm.light = prolongLight(level.material, coarseWarm.light, fine, fineFactors.active);
  warm.fromCoarserGrid = true;
  if (report) {
    report->levels = below.levels + 1;
    report->steps = below.steps + result.stepsRun;
    report->ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
  }
  return true;
}

std::array<std::vector<float>, 3> prolongLight(const MaterialGrid& coarse, const std::array<std::vector<float>, 3>& light,
                                               const MaterialGrid& fine, const std::vector<unsigned char>& fineActive) {
  const GridFrame& f = fine.frame;
  const double ratio = f.cellSize / coarse.frame.cellSize;
  const float scale = float(ratio * ratio);
  std::array<std::vector<float>, 3> out;
  for (auto& channel : out) channel.assign(f.cellCount(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<int>(0, f.dims.z), [&](const tbb::blocked_range<int>& zs) {
    for (int z = zs.begin(); z < zs.end(); ++z)
      for (int y = 0; y < f.dims.y; ++y)
        for (int x = 0; x < f.dims.x; ++x) {
          const std::size_t i = f.index(x, y, z);
          if (!fineActive[i]) continue;
          const glm::dvec3 centre = f.origin + f.cellSize * (glm::dvec3(x, y, z) + 0.5);
          std::size_t cells[8];
          float weights[8];
          const int used = activeTrilinearWeights(coarse, centre, cells, weights);
          for (int ch = 0; ch < 3; ++ch) {
            float sum = 0.0f;
            for (int k = 0; k < used; ++k) sum += weights[k] * light[ch][cells[k]];
            out[ch][i] = scale * sum;
          }
        }
  });
  return out;
}

}  // namespace sslpv

// The brush engine's free functions: falloff profiles, brush validation and the paint
// targets (formulas and conventions in brush_engine.h). Kept apart from the engine's
// painting and history so each file stays readable.
#include <algorithm>
#include <cmath>

#include "editor/brush_engine.h"
#include "volume/core/error.h"
#include "volume/scene/scene.h"

namespace sslpv {

using openvdb::Vec3s;

double falloffWeight(BrushFalloff falloff, double u) {
  if (!(u <= 1.0)) return 0.0;
  u = std::max(u, 0.0);
  switch (falloff) {
    case BrushFalloff::Constant:
      return 1.0;
    case BrushFalloff::Linear:
      return 1.0 - u;
    case BrushFalloff::Smooth:
      return 1.0 - u * u * (3.0 - 2.0 * u);
    case BrushFalloff::Gaussian: {
      const double edge = std::exp(-4.5);
      return (std::exp(-4.5 * u * u) - edge) / (1.0 - edge);
    }
  }
  return 0.0;
}

std::string brushProblem(const Brush& b) {
  auto finite3 = [](const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  auto minOf = [](const glm::dvec3& v) { return std::min(v.x, std::min(v.y, v.z)); };
  auto maxOf = [](const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); };
  if (!(b.radius > 0.0) || !std::isfinite(b.radius)) return "radius: must be a positive finite number";
  if (!(b.strength >= 0.0 && b.strength <= 1.0)) return "strength: must be in [0, 1]";
  if (!(b.depth >= 0.0) || !std::isfinite(b.depth)) return "depth: must be a non-negative finite number";
  if (b.mirror && (b.mirror->axis < 0 || b.mirror->axis > 2)) return "mirror.axis: must be x, y or z";
  if (b.mirror && b.mirror->at && !std::isfinite(*b.mirror->at)) return "mirror.at: must be finite";
  const bool valued = b.mode == BrushMode::Set || b.mode == BrushMode::Add || b.mode == BrushMode::Multiply;
  switch (b.channel) {
    case BrushChannel::All:
      if (valued) return "channel: mode set, add and multiply need a channel";
      return {};
    case BrushChannel::Colour:
      if (b.mode != BrushMode::Set) return "mode: the colour form takes mode set only";
      // Checked at the largest bound any ior allows; the engine checks its own ior's.
      return artistParamsProblem(b.artist, 1.0);
    case BrushChannel::AlbedoMfp:
    case BrushChannel::Preset:
      if (b.mode != BrushMode::Set) return "mode: channels albedo_mfp and preset take mode set only";
      if (b.channel == BrushChannel::Preset) {
        if (!presetMaterial(b.preset, 0.0f, 1.0))
          return "value: unknown preset \"" + b.preset + "\" (accepted: " + presetNames() + ")";
        return {};
      }
      if (!finite3(b.albedo) || minOf(b.albedo) < 0.0 || maxOf(b.albedo) > 1.0)
        return "value.albedo: must be in [0, 1]";
      if (!finite3(b.meanFreePath) || !(minOf(b.meanFreePath) > 0.0))
        return "value.mean_free_path: must be positive and finite";
      return {};
    case BrushChannel::SigmaT:
    case BrushChannel::SigmaS:
      if (!valued) return {};
      if (!finite3(b.rgb)) return "value: must be finite";
      if (b.mode != BrushMode::Add && minOf(b.rgb) < 0.0)
        return b.mode == BrushMode::Set ? "value: sigma must be non-negative" : "value: factor must be non-negative";
      return {};
    case BrushChannel::G:
      if (!valued) return {};
      if (!std::isfinite(b.scalar)) return "value: must be finite";
      if (b.mode == BrushMode::Set && !(std::abs(b.scalar) <= double(kBrushMaxG)))
        return "value: g must be in [-0.99, 0.99]";
      return {};
  }
  return {};
}

std::shared_ptr<MaterialSet> makeEmptyMaterialSet(const MaterialSample& base, double voxelSize,
                                                  const std::string& units) {
  initializeOpenVdb();
  if (!(voxelSize > 0.0) || !std::isfinite(voxelSize))
    throw InputError("material set: voxel size must be positive, got " + std::to_string(voxelSize));
  auto set = std::make_shared<MaterialSet>();
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxelSize);
  set->sigmaT = openvdb::Vec3SGrid::create(Vec3s(base.sigmaT.x, base.sigmaT.y, base.sigmaT.z));
  set->sigmaS = openvdb::Vec3SGrid::create(Vec3s(base.sigmaS.x, base.sigmaS.y, base.sigmaS.z));
  set->g = openvdb::FloatGrid::create(base.g);
  set->sigmaT->setName("sigma_t");
  set->sigmaS->setName("sigma_s");
  set->g->setName("g");
  for (openvdb::GridBase* grid :
       {static_cast<openvdb::GridBase*>(set->sigmaT.get()), static_cast<openvdb::GridBase*>(set->sigmaS.get()),
        static_cast<openvdb::GridBase*>(set->g.get())})
    grid->setTransform(transform->copy());
  set->sigmaT->setVectorType(openvdb::VEC_INVARIANT);
  set->sigmaS->setVectorType(openvdb::VEC_INVARIANT);
  set->units = units;
  set->creator = "sslpv paint";
  return set;
}

PaintTarget makePaintTarget(const Scene& scene) {
  PaintTarget target;
  // Loaded in rest space so the rest bounds (and the default voxel size) are exact, then
  // moved to world space with the same arithmetic as loadMesh(source, transform).
  TriangleMesh mesh = loadMesh(scene.mesh, Transform{});
  target.restBounds = mesh.bounds();
  target.restToWorld = scene.transform.matrix();
  for (glm::vec3& p : mesh.positions) p = glm::vec3(target.restToWorld * glm::dvec4(glm::dvec3(p), 1.0));
  requireClosedMesh(mesh);
  target.base = scene.material.base;
  target.sceneUnitInMm = scene.unitInMm;
  target.ior = scene.material.ior;
  target.worldMesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  if (scene.material.vdb) {
    const std::shared_ptr<const MaterialSet> loaded = loadMaterialSet(*scene.material.vdb);
    // The loaded grids may be shared (and are const): paint copies.
    target.set = deepCopy(*loaded);
  } else {
    const glm::dvec3 extent = target.restBounds.extent();
    const double voxel = std::max(extent.x, std::max(extent.y, extent.z)) / kDefaultVoxelsPerExtent;
    target.set = makeEmptyMaterialSet(scene.material.base, voxel, scene.units);
  }
  return target;
}

}  // namespace sslpv

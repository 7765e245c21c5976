#include "volume/material/scene_object.h"

#include <algorithm>
#include <chrono>

#include "volume/core/error.h"
#include "volume/core/strict_json.h"
#include "volume/material/material_field.h"

namespace sslpv {

SceneObject::SceneObject(const Scene& scene)
    : base_(scene.material.base),
      vdbName_(scene.material.vdb ? scene.material.vdb->string() : std::string("material set")),
      unitInMm_(scene.unitInMm),
      worldToRest_(glm::inverse(scene.transform.matrix())),
      sceneFile_(scene.file),
      transform_(scene.transform),
      deformers_(scene.deformers) {
  const auto start = std::chrono::steady_clock::now();
  try {
    if (scene.mesh.animated()) {
      auto skinned = std::make_shared<SkinnedMesh>(loadSkinnedMesh(scene.mesh.path));
      // loadMesh reorients an inside-out file; the rest mesh of a skinned one is kept as
      // the file winds it, the posed copies being oriented by loadMesh in setTime.
      restMesh_ = skinned->rest;
      requireClosedMesh(restMesh_);
      skinned_ = std::move(skinned);
    } else if (deformers_.empty()) {
      mesh_ = loadMesh(scene.mesh, scene.transform);
      requireClosedMesh(mesh_);
    } else {
      // Kept in rest space: every pose starts from it, and the material set lives there.
      restMesh_ = loadMesh(scene.mesh, Transform{});
      requireClosedMesh(restMesh_);
    }
  } catch (const InputError& e) {
    // The mesh's own message names a primitive ("box") or the mesh file; which scene and
    // key it came from is known only here.
    if (scene.file.empty()) throw;
    const char* key = scene.mesh.kind == MeshSource::Kind::File ? "mesh.path" : "mesh";
    throw InputError(scene.file.string() + ": " + key + ": " + e.what());
  }
  if (skinned_) {
    try {
      clip_ = &skinned_->skin.clips[selectClip(*skinned_, scene.mesh.animationName, scene.mesh.animationIndex)];
    } catch (const InputError& e) {
      if (scene.file.empty()) throw;
      throw InputError(scene.file.string() + ": mesh.animation: " + e.what());
    }
    std::vector<glm::dvec3> rest(restMesh_.positions.begin(), restMesh_.positions.end());
    restGrid_ = std::make_shared<const PointGrid>(std::move(rest));
  }
  if (deformed()) {
    setTime(scene.time);
    animationBounds_ = boundsOverAnimation();
  }
  bounds_ = mesh_.bounds();
  setMaterialSet(scene.material.vdb ? loadMaterialSet(*scene.material.vdb) : nullptr);
  loadMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::vector<glm::vec3> SceneObject::posedPositions(double t, const std::string& file,
                                                   std::shared_ptr<const SpaceDeformation>* pose) const {
  if (skinned_) {
    auto skin = std::make_shared<const SkinPose>(*skinned_, restGrid_, clip_, t);
    std::vector<glm::vec3> positions = skinnedPositions(*skin, file, t);
    // Zero joint scales or inverse bind matrices squash the mesh flat; left alone, that
    // surfaced as a grid error naming neither the file nor the key.
    TriangleMesh posed;
    posed.positions = positions;
    posed.triangles = restMesh_.triangles;
    if (!(std::abs(signedVolume(posed)) > 1e-6 * std::abs(signedVolume(restMesh_))))
      throw InputError((file.empty() ? std::string() : file + ": ") + "mesh.animation: at t = " + formatNumber(t) +
                       " the pose of " + restMesh_.name +
                       " encloses no volume (check its joint scales and inverse bind matrices)");
    if (pose) *pose = std::move(skin);
    return positions;
  }
  auto stack = std::make_shared<const DeformationPose>(deformers_, t);
  std::vector<glm::vec3> positions = deformPositions(restMesh_.positions, *stack, file, t);
  if (pose) *pose = std::move(stack);
  return positions;
}

void SceneObject::setTime(double t) {
  if (!deformed()) return;
  std::shared_ptr<const SpaceDeformation> pose;
  MeshSource posed;
  posed.kind = MeshSource::Kind::InMemory;
  auto deformed = std::make_shared<TriangleMesh>(restMesh_);
  deformed->positions = posedPositions(t, sceneFile_.string(), &pose);
  posed.mesh = std::move(deformed);
  // The transform's range check and orientation, as for a static mesh. Every deformer
  // keeps orientation (a positive Jacobian on its domain), so nothing is turned here; a
  // skinned pose that inverts some triangles is turned back, silently (warnReoriented).
  TriangleMesh mesh = loadMesh(posed, transform_, false);
  mesh_ = std::move(mesh);
  bounds_ = mesh_.bounds();
  pose_ = std::move(pose);
  if (field_) setMaterialSet(set_);
}

Bounds SceneObject::boundsOverAnimation() const {
  // Every key's time, and between the first and last key a sampling fine enough that a
  // pose between samples stays within a fraction of a cell of their union (a 90° bend
  // over 64 samples moves a point by under 2.5 % of its radius between them).
  constexpr int kSamples = 64;
  std::vector<double> times{0.0};  // scenes often render t = 0 with keys elsewhere
  double first = 1e300, last = -1e300;
  for (const Deformer& d : deformers_)
    for (const Keyframe& k : d.amount.keys) {
      times.push_back(k.t);
      first = std::min(first, k.t);
      last = std::max(last, k.t);
    }
  if (clip_) {
    // Between keys a joint turns by slerp, smoothly, so the 64 samples cover the clip as
    // they cover a deformer; the keys themselves are added too.
    first = clip_->start();
    last = clip_->end();
    for (const SkinChannel& c : clip_->channels)
      for (const auto* keys : {&c.translation.times, &c.rotation.times, &c.scale.times})
        times.insert(times.end(), keys->begin(), keys->end());
  }
  for (int i = 0; first < last && i <= kSamples; ++i) times.push_back(first + (last - first) * i / kSamples);
  // A baked clip keys every frame of every joint: a few hundred poses bound it as well.
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  constexpr std::size_t kMaxPoses = 512;
  if (times.size() > kMaxPoses) {
    std::vector<double> kept;
    for (std::size_t i = 0; i < kMaxPoses; ++i) kept.push_back(times[i * (times.size() - 1) / (kMaxPoses - 1)]);
    times.swap(kept);
  }
  const glm::dmat4 restToWorld = glm::inverse(worldToRest_);
  Bounds bounds = bounds_.empty() ? mesh_.bounds() : bounds_;
  for (double t : times) {
    std::vector<glm::vec3> posed;
    try {
      posed = posedPositions(t, std::string(), nullptr);
    } catch (const InputError&) {
      continue;  // the mesh folds at t: setTime refuses that time, so its pose need not fit
    }
    for (const glm::vec3& p : posed) bounds.extend(glm::dvec3(restToWorld * glm::dvec4(glm::dvec3(p), 1.0)));
  }
  return bounds;
}

void SceneObject::setMaterialSet(std::shared_ptr<const MaterialSet> set) {
  double sigmaScale = 1.0;
  if (set) {
    const auto fileUnit = unitInMm(set->units);
    if (!fileUnit)
      throw InputError(vdbName_ + ": unknown units '" + set->units + "' in file metadata (expected mm, cm, m or in)");
    // σ per file unit -> σ per scene unit.
    sigmaScale = unitInMm_ / *fileUnit;
  }
  set_ = std::move(set);
  field_ = std::make_unique<MaterialField>(base_, set_, worldToRest_, sigmaScale, pose_);
}

}  // namespace sslpv

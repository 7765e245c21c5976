#include "volume/scene_object.h"

#include <chrono>

#include "volume/error.h"

namespace sslpv {

SceneObject::SceneObject(const Scene& scene)
    : base_(scene.material.base),
      vdbName_(scene.material.vdb ? scene.material.vdb->string() : std::string("material set")),
      unitInMm_(scene.unitInMm),
      worldToRest_(glm::inverse(scene.transform.matrix())) {
  const auto start = std::chrono::steady_clock::now();
  try {
    mesh_ = loadMesh(scene.mesh, scene.transform);
    requireClosedMesh(mesh_);
  } catch (const InputError& e) {
    // The mesh's own message names a primitive ("box") or the mesh file; which scene and
    // key it came from is known only here.
    if (scene.file.empty()) throw;
    const char* key = scene.mesh.kind == MeshSource::Kind::File ? "mesh.path" : "mesh";
    throw InputError(scene.file.string() + ": " + key + ": " + e.what());
  }
  bounds_ = mesh_.bounds();
  setMaterialSet(scene.material.vdb ? loadMaterialSet(*scene.material.vdb) : nullptr);
  loadMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
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
  field_ = std::make_unique<MaterialField>(base_, set_, worldToRest_, sigmaScale);
}

}  // namespace sslpv

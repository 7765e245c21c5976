// `sslpv export --pbrt` on scenes the loader accepts: the object is built (mesh, material
// set), the medium sampled and the pbrt text written, to memory instead of a file. The
// scratch folder holds what scenes may name: "mesh.obj" and "set.vdb" (and the example
// names "pebble.obj" and "marble_veins.vdb"), small and valid.
#include <cstdint>
#include <fstream>
#include <sstream>

#include "fuzz/fuzz_support.h"
#include "volume/eval/pbrt_export.h"
#include "volume/material/scene_object.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  using namespace sslpv::fuzz;
  for (const char* name : {"mesh.obj", "pebble.obj"}) std::ofstream(scratchDir() / name) << smallClosedObj();
  for (const char* name : {"set.vdb", "marble_veins.vdb"}) writeSmallMaterialSet(scratchDir() / name);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sslpv;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // A small grid keeps an input fast; which one varies with the input.
  const int grid = 2 + int(size % 7);
  fuzz::expectOnlyInputErrors([&] {
    const Scene scene = parseScene(text, fuzz::scratchDir() / "scene.json");
    const SceneObject object(scene);
    const PbrtMedium medium = samplePbrtMedium(object, grid);
    std::ostringstream out;
    writePbrtScene(out, scene, object.mesh(), medium, "scene.exr");
    if (!out) fuzz::finding("writing the pbrt scene to memory failed");
  });
  return 0;
}

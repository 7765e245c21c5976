// Material sets as `render`, `inspect` and the editor read them: loadMaterialSet goes
// through the isolated reader (a forked child parses the untrusted bytes, this process
// parses only the child's re-serialized stream) and then validates every voxel; the
// loaded set is then sampled as the renderers do. The child's crashes are the product's
// own business (they become InputErrors); findings are what reaches this process.
#include <cstdint>
#include <sstream>

#include "fuzz/fuzz_support.h"
#include "volume/material/material_field.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sslpv;
  const std::filesystem::path file = fuzz::writeScratchFile("set.vdb", data, size);
  fuzz::expectOnlyInputErrors([&] {
    std::ostringstream report;
    (void)inspectVdbFile(file, report);
  });
  fuzz::expectOnlyInputErrors([&] {
    std::shared_ptr<const MaterialSet> set = loadMaterialSet(file);
    const MaterialSample base{glm::vec3(1.0f), glm::vec3(0.5f), 0.0f};
    const MaterialField field(base, set, glm::dmat4(1.0), 1.0);
    const MaterialField::Sampler sampler = field.sampler();
    const openvdb::CoordBBox box = set->sigmaT->evalActiveVoxelBoundingBox();
    const openvdb::Vec3d lo = set->sigmaT->indexToWorld(box.min()), hi = set->sigmaT->indexToWorld(box.max());
    const glm::dvec3 a(lo.x(), lo.y(), lo.z()), b(hi.x(), hi.y(), hi.z());
    for (double t : {0.0, 0.37, 0.5, 1.0}) {
      const MaterialSample s = sampler.sample(a + t * (b - a));
      if (!(s.sigmaT.x >= 0.0f) || !(s.sigmaS.x >= 0.0f) || !(s.g > -1.0f && s.g < 1.0f))
        fuzz::finding("a validated material set samples to an invalid material");
    }
    (void)sampler.boxAverage(glm::min(a, b), glm::max(a, b));
  });
  return 0;
}

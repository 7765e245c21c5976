// The strict scene loader (volume/scene/scene.cpp over volume/core/strict_json.cpp): any bytes as a
// scene file must give a Scene or an InputError.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "volume/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sslpv;
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expectOnlyInputErrors([&] {
    const Scene scene = parseScene(text, fuzz::scratchDir() / "scene.json");
    // The flags path re-validates the parsed settings the way `render --grid` does.
    LpvFlags flags;
    flags.grid = scene.lpv.resolution;
    flags.shadowMap = scene.lpv.shadowMap;
    (void)applyLpvFlags(scene.lpv, flags);
  });
  return 0;
}

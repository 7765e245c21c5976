// The stroke-file reader (editor/stroke_io.cpp): any bytes give strokes or an InputError,
// and strokes it accepts survive formatStrokes -> parseStrokes unchanged (the header's
// promise, which `sslpv paint` replays and the editor saves by).
#include <cstdint>
#include <string>

#include "editor/stroke_io.h"
#include "fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sslpv;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::filesystem::path file = fuzz::scratchDir() / "strokes.json";
  fuzz::expectOnlyInputErrors([&] {
    const std::vector<Stroke> strokes = parseStrokes(text, file);
    const std::string written = formatStrokes(strokes);
    std::vector<Stroke> reread;
    try {
      reread = parseStrokes(written, file);
    } catch (const InputError& e) {
      fuzz::finding(std::string("formatStrokes wrote a file parseStrokes rejects: ") + e.what() + "\n" + written);
    }
    if (formatStrokes(reread) != written)
      fuzz::finding("strokes changed in a format/parse round trip:\n" + written + "\n" + formatStrokes(reread));
  });
  return 0;
}

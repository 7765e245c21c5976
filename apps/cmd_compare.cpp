#include "apps/cmd_compare.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "apps/cli_output.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"
#include "volume/eval/image_metrics.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

std::string lowerExtension(const std::string& file) {
  std::string ext = fs::path(file).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// A or B. PNG holds exposure-scaled, clipped, 8-bit sRGB: relative errors of linear
/// radiance computed from it would measure the tone mapping, so it is refused.
Image readLinearImage(const std::string& file, const char* role) {
  if (lowerExtension(file) == ".png")
    throw InputError(file + ": " + role + " is a PNG (tone-mapped, clipped 8-bit sRGB); compare needs linear " +
                     "radiance: render with -o .exr or .pfm");
  return readImage(file);
}

void requireFinite(const Image& image, const std::string& file) {
  if (const auto p = firstNonFinitePixel(image)) {
    const glm::vec3 v = image.at(p->x, p->y);
    const bool nan = std::isnan(v.r) || std::isnan(v.g) || std::isnan(v.b);
    throw InputError(file + ": pixel x=" + std::to_string(p->x) + ", y=" + std::to_string(p->y) +
                     " (row 0 at the top) is " + (nan ? "NaN" : "infinite"));
  }
}

std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string sizeText(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void printTable(const CompareArgs& args, const Image& a, const ImageMetrics& m) {
  std::printf("A (test)       %s\n", args.a.c_str());
  std::printf("B (reference)  %s\n", args.b.c_str());
  std::printf("image          %dx%d", a.width, a.height);
  if (args.block > 1) std::printf(", %dx%d blocks -> %dx%d", args.block, args.block, m.width, m.height);
  std::printf("\nmask           %s: %zu of %d %s\n", args.mask.c_str(), m.maskPixels, m.width * m.height,
              args.block > 1 ? "blocks" : "pixels");
  std::printf("mean A         %.6g   (RGB %.6g %.6g %.6g)\n", m.meanA, m.meanARgb.r, m.meanARgb.g, m.meanARgb.b);
  std::printf("mean B         %.6g   (RGB %.6g %.6g %.6g)\n", m.meanB, m.meanBRgb.r, m.meanBRgb.g, m.meanBRgb.b);
  std::printf("mean A / B     %.6g\n", m.meanRatio);
  std::printf("RMSE           %.6g\n", m.rmse);
  std::printf("relative MSE   %.6g   ((A-B)^2 / (B^2 + eps), eps = (0.01 mean B)^2 = %.3g)\n", m.relativeMse,
              m.relativeMseEpsilon);
  std::printf("mean rel. err  %.6g   (|A-B| / max(|B|, 0.01 mean B = %.3g); RGB %.4g %.4g %.4g)\n",
              m.meanRelativeError, m.relativeFloor, m.meanRelativeErrorRgb.r, m.meanRelativeErrorRgb.g,
              m.meanRelativeErrorRgb.b);
  std::printf("SSIM           %.6g   (luminance, Gaussian 11x11 sigma 1.5, L = max B luminance = %.6g)\n", m.ssim,
              m.ssimRange);
}

}  // namespace

CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "compare", "Error metrics of a test image A against a reference B over the object's pixels");
  cmd->add_option("a", args.a, "Test image A (.exr or .pfm, linear), e.g. from sslpv render")->required();
  cmd->add_option("b", args.b, "Reference image B (.exr or .pfm, linear), e.g. from sslpv reference")
      ->required();
  cmd->add_option("--mask", args.mask,
                  "'auto' (pixels non-zero in A or B) or a mask image of the same size (value > 0; "
                  "write ./auto for a file named auto)");
  cmd->add_option("--block", args.block,
                  "Average KxK blocks first (a block is in the mask when all its pixels are) to "
                  "suppress reference noise");
  cmd->add_option("--json", args.json, "Also write the numbers to this JSON file (atomically)");
  cmd->add_option("--ratio-map", args.ratioMap,
                  "Also write where A and B differ (.png/.exr/.pfm): R, G, B panels, white where equal, "
                  "red where A is brighter, blue where darker, full colour at x2 / x1/2; per block with --block");
  return cmd;
}

int runCompare(const CompareArgs& args) {
  const auto start = CliClock::now();
  if (args.block < 1) throw InputError("--block: must be at least 1, got " + std::to_string(args.block));
  if (!args.json.empty()) requireWritableOutput(args.json);
  if (!args.ratioMap.empty()) {
    if (!isSupportedImageExtension(args.ratioMap))
      throw InputError(args.ratioMap + ": --ratio-map must end in .png, .exr or .pfm");
    requireWritableOutput(args.ratioMap);
  }

  const Image a = readLinearImage(args.a, "A");
  requireFinite(a, args.a);
  const Image b = readLinearImage(args.b, "B");
  requireFinite(b, args.b);
  if (a.width != b.width || a.height != b.height)
    throw InputError(args.b + ": reference is " + sizeText(b) + " but " + args.a + " is " + sizeText(a));
  if (args.block > std::min(a.width, a.height))
    throw InputError("--block: " + std::to_string(args.block) + " is larger than the images (" + args.a + " is " +
                     sizeText(a) + ")");

  PixelMask mask;
  if (args.mask == "auto") {
    mask = autoMask(a, b);
    if (mask.count() == 0)
      throw InputError(args.a + " and " + args.b + " are both zero everywhere: --mask auto is empty");
  } else {
    const Image maskImage = readImage(args.mask);
    requireFinite(maskImage, args.mask);
    if (maskImage.width != a.width || maskImage.height != a.height)
      throw InputError(args.mask + ": mask is " + sizeText(maskImage) + " but the images are " + sizeText(a));
    mask = maskFromImage(maskImage);
    if (mask.count() == 0) throw InputError(args.mask + ": the mask is empty (no pixel > 0)");
  }

  Image blockA = a, blockB = b;
  if (args.block > 1) {
    const std::size_t pixels = mask.count();
    blockA = blockAverage(a, args.block);
    blockB = blockAverage(b, args.block);
    mask = blockMask(mask, args.block);
    if (mask.count() == 0)
      throw InputError((args.mask == "auto" ? args.a + " and " + args.b : args.mask) + ": none of the " +
                       std::to_string(args.block) + "x" + std::to_string(args.block) +
                       " blocks lies entirely inside the mask (" + std::to_string(pixels) +
                       " pixels); use a smaller --block");
  }

  // Relative metrics and SSIM's range are defined against a positive reference.
  double sumB = 0.0, maxLuminanceB = 0.0;
  for (std::size_t i = 0; i < blockB.pixels.size(); ++i)
    if (mask.inside[i]) {
      sumB += double(blockB.pixels[i].r) + blockB.pixels[i].g + blockB.pixels[i].b;
      maxLuminanceB = std::max(maxLuminanceB, luminance(blockB.pixels[i]));
    }
  if (!(sumB > 0.0) || !(maxLuminanceB > 0.0))
    throw InputError(args.b + ": the reference is not positive over the mask (" +
                     std::to_string(mask.count()) + (args.block > 1 ? " blocks" : " pixels") + ", mean " +
                     shortNumber(sumB / (3.0 * double(mask.count()))) +
                     "): relative errors need a positive reference");

  const ImageMetrics metrics = computeImageMetrics(blockA, blockB, mask);
  if (!args.json.empty()) {
    CompareSource source{args.a, args.b, args.mask, a.width, a.height, args.block};
    const std::string text = compareJson(source, metrics);
    writeAtomically(args.json, [&](const fs::path& temp) {
      std::ofstream out(temp, std::ios::binary);
      out << text;
      out.close();
      if (!out) throwWriteFailed(args.json, errno);
    });
  }
  Image map;
  if (!args.ratioMap.empty()) {
    map = ratioMap(blockA, blockB, mask, metrics.relativeFloor, args.block);
    writeImage(map, args.ratioMap);
  }
  printTable(args, a, metrics);
  if (!args.json.empty()) printWrote(args.json, "compare metrics", start);
  if (!args.ratioMap.empty()) printWrote(args.ratioMap, imageSizeText(map), start);
  return 0;
}

}  // namespace sslpv

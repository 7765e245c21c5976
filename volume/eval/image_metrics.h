#pragma once
// Error metrics between a test image A (an SSLPV render) and a reference image B (the
// path tracer), over the pixels that show the object (docs/design.md §7 "Accuracy methodology").
//
// Definitions (n = masked pixels, sums over masked pixels p and channels c = R, G, B):
//   mean_B      = Σ B / (3n), likewise mean_A; ratio = mean_A / mean_B (a global energy
//                 bias shows here even when it is spread thinly over every pixel).
//   RMSE        = sqrt(Σ (A−B)² / (3n)), in radiance units.
//   rel. MSE    = Σ (A−B)² / (B² + ε) / (3n), ε = (0.01 · mean_B)².
//   mean rel.   = Σ |A−B| / max(|B|, 0.01 · mean_B) / (3n).
//   SSIM        = Wang et al. 2004 on luminance Y = 0.2126 R + 0.7152 G + 0.0722 B,
//                 Gaussian window 11×11, σ 1.5, C1 = (0.01 L)², C2 = (0.03 L)², L = the
//                 largest reference luminance in the mask, averaged over the windows
//                 centred on masked pixels.
// Why the 1 % floor: the reference is a Monte Carlo estimate and the object has dark
// regions (shadowed sides, strongly absorbed channels) where B is near or exactly 0; a
// plain relative error there is noise divided by nothing and would swamp the mean. Below
// 1 % of the mean reference value the error counts as absolute error relative to that
// floor, above it as a true relative error (so A = 1.1 B gives a mean relative error of
// exactly 0.1 wherever B ≥ 0.01 mean_B). The floor scales with B, so every metric but
// RMSE is unchanged when both images are multiplied by the same factor (a change of
// exposure or light units). Both relative metrics work per channel, like RMSE, so a
// chromatic error (wrong red diffusion) counts as much as a luminance error.
// Why L = the reference's maximum: linear radiance has no fixed range; the reference's
// brightest object pixel is the range the SSIM constants stabilise against. Fireflies
// in a noisy reference raise L (and SSIM): block-average first (blockAverage) to tame
// them.
// SSIM windows reach outside the mask (the silhouette is part of the structure); near
// the image border the Gaussian weights are renormalised over the pixels inside the
// image, so images smaller than the window (block images) still get an SSIM.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "volume/core/image_io.h"

namespace sslpv {

/// The relative metrics' floor, as a fraction of the mean reference value over the mask.
constexpr double kRelativeFloorFraction = 1e-2;
constexpr int kSsimRadius = 5;  ///< 11×11 window
constexpr double kSsimSigma = 1.5;
constexpr double kSsimK1 = 0.01;
constexpr double kSsimK2 = 0.03;

/// Which pixels show the object; row 0 is the top row, like Image.
struct PixelMask {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> inside;
  PixelMask() = default;
  PixelMask(int w, int h) : width(w), height(h), inside(std::size_t(w) * h, 0) {}
  bool at(int x, int y) const { return inside[std::size_t(y) * width + x] != 0; }
  void set(int x, int y, bool value) { inside[std::size_t(y) * width + x] = value ? 1 : 0; }
  std::size_t count() const;
};

/// Rec. 709 luminance of linear RGB (the weights sum to 1).
double luminance(const glm::vec3& rgb);

/// Pixels where A or B is non-zero in any channel: both renderers write exact 0 for the
/// background. Precondition (std::invalid_argument): same size.
PixelMask autoMask(const Image& a, const Image& b);

/// Pixels whose value is > 0 in any channel (a grey mask has equal channels).
PixelMask maskFromImage(const Image& image);

/// The first pixel (row by row from the top-left) holding NaN or ±Inf in any channel.
std::optional<glm::ivec2> firstNonFinitePixel(const Image& image);

/// Mean over each K×K block; the result is floor(W/K) × floor(H/K): the incomplete
/// blocks at the right and bottom edges are dropped so that every block averages the
/// same number of pixels (equal noise). Precondition (std::invalid_argument): 1 ≤ K ≤
/// min(W, H).
Image blockAverage(const Image& image, int k);

/// A block is in the mask when all of its K×K pixels are: a block straddling the
/// silhouette would average object with background, and the renderers' sub-pixel
/// disagreement on the outline would show up as a large relative error that says
/// nothing about light transport. Same size rule and precondition as blockAverage.
PixelMask blockMask(const PixelMask& mask, int k);

/// SSIM as defined above, averaged over windows centred on masked pixels, against
/// dynamic range `range`. Preconditions (std::invalid_argument): equal sizes, a non-empty
/// mask, range > 0.
double ssim(const Image& a, const Image& b, const PixelMask& mask, double range);

/// Largest per-channel |a - b| / |b| over the whole image (|b| floored at 1e-6 of b's
/// peak, so black background pixels compare absolutely); infinity for different sizes or
/// a non-finite pixel. For "these two renders are the same frame" checks.
double maxRelativeDifference(const Image& a, const Image& b);

struct ImageMetrics {
  int width = 0, height = 0;   ///< of the images the metrics were computed on
  std::size_t maskPixels = 0;  ///< pixels (or blocks) in the mask
  double meanA = 0, meanB = 0, meanRatio = 0;  ///< means over mask and channels; A / B
  glm::dvec3 meanARgb{0.0}, meanBRgb{0.0};     ///< per channel
  double rmse = 0;
  double relativeMse = 0, relativeMseEpsilon = 0;     ///< ε = (0.01 mean_B)²
  double meanRelativeError = 0, relativeFloor = 0;    ///< floor = 0.01 mean_B
  glm::dvec3 meanRelativeErrorRgb{0.0};               ///< per channel (their mean is the above)
  double ssim = 0, ssimRange = 0;                     ///< L = max reference luminance
};

/// All metrics of A against reference B over `mask`. Preconditions (std::invalid_argument,
/// callers that read files check them first to name the file): equal sizes, finite
/// pixels, a non-empty mask, mean_B > 0 and a positive reference luminance in the mask.
ImageMetrics computeImageMetrics(const Image& a, const Image& b, const PixelMask& mask);

/// Where A and B disagree, per channel: three panels side by side (R, G, B), each pixel
/// (or block) of the images drawn as scale × scale pixels, white where A = B, towards full
/// red where A is brighter and full blue where it is darker, saturating at A / B = 2 and
/// 1/2 (the colour's depth is |log2(A / B)|). Values under `floor` count as the floor (the
/// relative metrics' floor, so reference noise in black regions does not paint the map);
/// where A and B are both under it the pixel is grey (kRatioMapBelowFloor): too dark to
/// compare relatively. Pixels outside the mask are black. Linear RGB in [0, 1], for
/// writeImage as PNG.
/// Preconditions (std::invalid_argument): equal sizes, scale ≥ 1, floor > 0.
constexpr float kRatioMapBelowFloor = 0.25f;
Image ratioMap(const Image& a, const Image& b, const PixelMask& mask, double floor, int scale);

/// Grid-layer bands (docs/accuracy.md "Grid-layer bands"): one surface pixel as the
/// shading reads the grid. `grid` holds the continuous grid coordinates (cell (i,j,k)
/// spans [i, i+1) per axis) of the point the shading reads, half a cell inside the
/// surface; `normal` the outward unit normal; `position` the world hit point, over which
/// the smooth part of the image is fitted.
struct GridBandSample {
  std::uint32_t pixel = 0;  ///< y · width + x
  glm::dvec3 grid{0.0}, normal{0.0}, position{0.0};
};

struct GridBandAmplitude {
  /// Per grid axis: the RMS over the phase bins (pixel-weighted) of the mean relative
  /// deviation of luminance from its smooth fit, a fraction (0.01 = 1 %).
  glm::dvec3 axis{0.0};
  double amplitude = 0.0;  ///< the largest of `axis`
  /// Per axis: what the given per-pixel standard error alone adds to `axis` in expectation
  /// (zero without one): the noise floor of a Monte Carlo image.
  glm::dvec3 noise{0.0};
  std::size_t pixels = 0;  ///< pixels that took part (inside a patch, away from its rim)
};

/// Phase bins over kGridBandPeriod cells: a pattern locked to the cell phase (period 1)
/// and one alternating between layers (period 2) both show.
constexpr int kGridBandBins = 16;
constexpr double kGridBandPeriod = 2.0;

/// The amplitude of the image's luminance pattern locked to the grid's cell layers. The
/// pixels are split into patches of similar normal (within ~26°), each patch loses a rim
/// of kGridBandRim pixels (silhouette, edges: real, sharp changes no smooth fit follows),
/// and each pixel gets, per grid axis, a phase over kGridBandPeriod cells: its layer's
/// parity plus its read point's depth below the cell face the outward normal points
/// through. Per axis, log-luminance is fitted jointly by a quadratic in each patch's
/// tangent plane (the smooth lighting) and one offset per phase bin (the bands), so that
/// neither takes up the other; the axis reads the pixel-weighted RMS of the offsets. A
/// smooth image reads near zero however it is lit; bands that follow the cell layers read
/// their RMS amplitude. Texture that happens to line up with the cell layers counts too.
/// `standardError` (a path tracer's, same size as `image`) adds the expected noise
/// contribution. Patches under 64 pixels are left out. Preconditions
/// (std::invalid_argument): sample pixels inside the image, `standardError` of the same size.
constexpr int kGridBandRim = 2;
GridBandAmplitude gridBandAmplitude(const Image& image, const std::vector<GridBandSample>& samples,
                                    const Image* standardError = nullptr);

/// Where the numbers came from, for the JSON record.
struct CompareSource {
  std::string a, b;          ///< file names
  std::string mask;          ///< "auto" or the mask file
  int width = 0, height = 0;  ///< input image size (before block averaging)
  int block = 1;
};

/// One JSON object (schema in README "sslpv compare"), with a trailing newline.
std::string compareJson(const CompareSource& source, const ImageMetrics& metrics);

}  // namespace sslpv

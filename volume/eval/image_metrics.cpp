#include "volume/eval/image_metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace sslpv {
namespace {

void requireSameSize(const Image& a, const Image& b, const char* where) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument(std::string(where) + ": images are " + std::to_string(a.width) + "x" +
                                std::to_string(a.height) + " and " + std::to_string(b.width) + "x" +
                                std::to_string(b.height));
}

void requireMaskSize(const Image& image, const PixelMask& mask, const char* where) {
  if (mask.width != image.width || mask.height != image.height ||
      mask.inside.size() != std::size_t(mask.width) * std::size_t(mask.height))
    throw std::invalid_argument(std::string(where) + ": the mask is " + std::to_string(mask.width) + "x" +
                                std::to_string(mask.height) + ", the images " + std::to_string(image.width) +
                                "x" + std::to_string(image.height));
}

void requireBlockSize(int width, int height, int k, const char* where) {
  if (k < 1 || k > std::min(width, height))
    throw std::invalid_argument(std::string(where) + ": block size " + std::to_string(k) + " for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image");
}

/// Un-normalised 1D Gaussian taps for offsets −R..R.
std::array<double, 2 * kSsimRadius + 1> gaussianTaps() {
  std::array<double, 2 * kSsimRadius + 1> taps{};
  for (int d = -kSsimRadius; d <= kSsimRadius; ++d)
    taps[std::size_t(d + kSsimRadius)] = std::exp(-double(d * d) / (2.0 * kSsimSigma * kSsimSigma));
  return taps;
}

/// Per position along an axis of length n: the sum of the taps that fall inside [0, n).
/// The 2D window is separable, so the renormalisation of a window cut by the image
/// border is the product of the two axes' sums.
std::vector<double> tapSums(int n, const std::array<double, 2 * kSsimRadius + 1>& taps) {
  std::vector<double> sums(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i)
    for (int d = -kSsimRadius; d <= kSsimRadius; ++d)
      if (i + d >= 0 && i + d < n) sums[std::size_t(i)] += taps[std::size_t(d + kSsimRadius)];
  return sums;
}

/// Separable, un-normalised Gaussian filter of a W×H map; taps outside the image are
/// skipped (the caller divides by the tap sums).
std::vector<double> gaussianFilter(const std::vector<double>& map, int width, int height,
                                   const std::array<double, 2 * kSsimRadius + 1>& taps) {
  std::vector<double> rows(map.size(), 0.0), out(map.size(), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      for (int d = std::max(-kSsimRadius, -x); d <= std::min(kSsimRadius, width - 1 - x); ++d)
        sum += taps[std::size_t(d + kSsimRadius)] * map[std::size_t(y) * width + std::size_t(x + d)];
      rows[std::size_t(y) * width + x] = sum;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0.0;
      for (int d = std::max(-kSsimRadius, -y); d <= std::min(kSsimRadius, height - 1 - y); ++d)
        sum += taps[std::size_t(d + kSsimRadius)] * rows[std::size_t(y + d) * width + x];
      out[std::size_t(y) * width + x] = sum;
    }
  return out;
}

}  // namespace

std::size_t PixelMask::count() const {
  return std::size_t(std::count_if(inside.begin(), inside.end(), [](std::uint8_t v) { return v != 0; }));
}

double luminance(const glm::vec3& rgb) {
  return 0.2126 * double(rgb.r) + 0.7152 * double(rgb.g) + 0.0722 * double(rgb.b);
}

PixelMask autoMask(const Image& a, const Image& b) {
  requireSameSize(a, b, "autoMask");
  PixelMask mask(a.width, a.height);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      mask.set(x, y, a.at(x, y) != glm::vec3(0.0f) || b.at(x, y) != glm::vec3(0.0f));
  return mask;
}

PixelMask maskFromImage(const Image& image) {
  PixelMask mask(image.width, image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const glm::vec3& p = image.at(x, y);
      mask.set(x, y, p.r > 0.0f || p.g > 0.0f || p.b > 0.0f);
    }
  return mask;
}

std::optional<glm::ivec2> firstNonFinitePixel(const Image& image) {
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const glm::vec3& p = image.at(x, y);
      if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b)) return glm::ivec2(x, y);
    }
  return std::nullopt;
}

Image blockAverage(const Image& image, int k) {
  requireBlockSize(image.width, image.height, k, "blockAverage");
  Image out(image.width / k, image.height / k);
  const double inv = 1.0 / (double(k) * double(k));
  for (int by = 0; by < out.height; ++by)
    for (int bx = 0; bx < out.width; ++bx) {
      glm::dvec3 sum(0.0);
      for (int y = by * k; y < (by + 1) * k; ++y)
        for (int x = bx * k; x < (bx + 1) * k; ++x) sum += glm::dvec3(image.at(x, y));
      out.at(bx, by) = glm::vec3(sum * inv);
    }
  return out;
}

PixelMask blockMask(const PixelMask& mask, int k) {
  requireBlockSize(mask.width, mask.height, k, "blockMask");
  PixelMask out(mask.width / k, mask.height / k);
  for (int by = 0; by < out.height; ++by)
    for (int bx = 0; bx < out.width; ++bx) {
      bool all = true;
      for (int y = by * k; y < (by + 1) * k && all; ++y)
        for (int x = bx * k; x < (bx + 1) * k && all; ++x) all = mask.at(x, y);
      out.set(bx, by, all);
    }
  return out;
}

double ssim(const Image& a, const Image& b, const PixelMask& mask, double range) {
  requireSameSize(a, b, "ssim");
  requireMaskSize(a, mask, "ssim");
  if (!(range > 0.0) || !std::isfinite(range))
    throw std::invalid_argument("ssim: the dynamic range must be positive, got " + std::to_string(range));
  const int w = a.width, h = a.height;
  const std::size_t n = std::size_t(w) * std::size_t(h);
  std::vector<double> ya(n), yb(n), yaa(n), ybb(n), yab(n);
  for (std::size_t i = 0; i < n; ++i) {
    ya[i] = luminance(a.pixels[i]);
    yb[i] = luminance(b.pixels[i]);
    yaa[i] = ya[i] * ya[i];
    ybb[i] = yb[i] * yb[i];
    yab[i] = ya[i] * yb[i];
  }
  const auto taps = gaussianTaps();
  const std::vector<double> sumX = tapSums(w, taps), sumY = tapSums(h, taps);
  const std::vector<double> fa = gaussianFilter(ya, w, h, taps), fb = gaussianFilter(yb, w, h, taps);
  const std::vector<double> faa = gaussianFilter(yaa, w, h, taps), fbb = gaussianFilter(ybb, w, h, taps);
  const std::vector<double> fab = gaussianFilter(yab, w, h, taps);
  const double c1 = (kSsimK1 * range) * (kSsimK1 * range);
  const double c2 = (kSsimK2 * range) * (kSsimK2 * range);
  double total = 0.0;
  std::size_t windows = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!mask.at(x, y)) continue;
      const std::size_t i = std::size_t(y) * w + x;
      const double norm = 1.0 / (sumX[std::size_t(x)] * sumY[std::size_t(y)]);
      const double mu_a = fa[i] * norm, mu_b = fb[i] * norm;
      const double var_a = faa[i] * norm - mu_a * mu_a;
      const double var_b = fbb[i] * norm - mu_b * mu_b;
      const double cov = fab[i] * norm - mu_a * mu_b;
      total += ((2.0 * mu_a * mu_b + c1) * (2.0 * cov + c2)) /
               ((mu_a * mu_a + mu_b * mu_b + c1) * (var_a + var_b + c2));
      ++windows;
    }
  if (windows == 0) throw std::invalid_argument("ssim: the mask is empty");
  return total / double(windows);
}

ImageMetrics computeImageMetrics(const Image& a, const Image& b, const PixelMask& mask) {
  requireSameSize(a, b, "computeImageMetrics");
  requireMaskSize(a, mask, "computeImageMetrics");
  if (firstNonFinitePixel(a) || firstNonFinitePixel(b))
    throw std::invalid_argument("computeImageMetrics: non-finite pixel");
  ImageMetrics m;
  m.width = a.width;
  m.height = a.height;
  m.maskPixels = mask.count();
  if (m.maskPixels == 0) throw std::invalid_argument("computeImageMetrics: the mask is empty");

  // First pass: the means, which set the floors of the relative metrics and L.
  glm::dvec3 sumA(0.0), sumB(0.0);
  double maxLuminanceB = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    if (!mask.inside[i]) continue;
    sumA += glm::dvec3(a.pixels[i]);
    sumB += glm::dvec3(b.pixels[i]);
    maxLuminanceB = std::max(maxLuminanceB, luminance(b.pixels[i]));
  }
  const double pixels = double(m.maskPixels), samples = 3.0 * pixels;
  m.meanARgb = sumA / pixels;
  m.meanBRgb = sumB / pixels;
  m.meanA = (sumA.r + sumA.g + sumA.b) / samples;
  m.meanB = (sumB.r + sumB.g + sumB.b) / samples;
  if (!(m.meanB > 0.0))
    throw std::invalid_argument("computeImageMetrics: the reference's mean over the mask is not positive");
  if (!(maxLuminanceB > 0.0))
    throw std::invalid_argument("computeImageMetrics: the reference has no positive luminance in the mask");
  m.meanRatio = m.meanA / m.meanB;
  m.relativeFloor = kRelativeFloorFraction * m.meanB;
  m.relativeMseEpsilon = m.relativeFloor * m.relativeFloor;

  double squared = 0.0, relativeSquared = 0.0;
  glm::dvec3 relative(0.0);
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    if (!mask.inside[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double va = a.pixels[i][c], vb = b.pixels[i][c];
      const double d = va - vb;
      squared += d * d;
      relativeSquared += d * d / (vb * vb + m.relativeMseEpsilon);
      relative[c] += std::abs(d) / std::max(std::abs(vb), m.relativeFloor);
    }
  }
  m.rmse = std::sqrt(squared / samples);
  m.relativeMse = relativeSquared / samples;
  m.meanRelativeErrorRgb = relative / pixels;
  m.meanRelativeError = (relative.r + relative.g + relative.b) / samples;
  m.ssimRange = maxLuminanceB;
  m.ssim = ssim(a, b, mask, m.ssimRange);
  return m;
}

std::string compareJson(const CompareSource& source, const ImageMetrics& m) {
  const nlohmann::ordered_json record = {
      {"a", source.a},
      {"b", source.b},
      {"mask", source.mask},
      {"width", source.width},
      {"height", source.height},
      {"block", source.block},
      {"metric_width", m.width},
      {"metric_height", m.height},
      {"mask_pixels", m.maskPixels},
      {"mean_a", m.meanA},
      {"mean_b", m.meanB},
      {"mean_ratio", m.meanRatio},
      {"mean_a_rgb", {m.meanARgb.r, m.meanARgb.g, m.meanARgb.b}},
      {"mean_b_rgb", {m.meanBRgb.r, m.meanBRgb.g, m.meanBRgb.b}},
      {"rmse", m.rmse},
      {"relative_mse", m.relativeMse},
      {"relative_mse_epsilon", m.relativeMseEpsilon},
      {"mean_relative_error", m.meanRelativeError},
      {"mean_relative_error_rgb", {m.meanRelativeErrorRgb.r, m.meanRelativeErrorRgb.g, m.meanRelativeErrorRgb.b}},
      {"relative_error_floor", m.relativeFloor},
      {"ssim", m.ssim},
      {"ssim_range", m.ssimRange},
  };
  return record.dump(2) + "\n";
}

Image ratioMap(const Image& a, const Image& b, const PixelMask& mask, double floor, int scale) {
  if (a.width != b.width || a.height != b.height || mask.width != a.width || mask.height != a.height)
    throw std::invalid_argument("ratioMap: A, B and the mask must have the same size");
  if (scale < 1 || !(floor > 0.0)) throw std::invalid_argument("ratioMap: scale must be >= 1 and floor > 0");
  Image map(3 * a.width * scale, a.height * scale);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (!mask.at(x, y)) continue;
      const glm::vec3 va = a.at(x, y), vb = b.at(x, y);
      for (int c = 0; c < 3; ++c) {
        // The metric's floor, so that noise in a near-black reference does not paint
        // the map: below it both sides count as the floor.
        const double ratio = std::max(double(va[c]), floor) / std::max(double(vb[c]), floor);
        const float shade = float(std::min(1.0, std::abs(std::log2(ratio))));
        glm::vec3 colour = ratio >= 1.0 ? glm::vec3(1.0f, 1.0f - shade, 1.0f - shade)
                                        : glm::vec3(1.0f - shade, 1.0f - shade, 1.0f);
        if (std::max(va[c], vb[c]) < floor) colour = glm::vec3(kRatioMapBelowFloor);
        for (int dy = 0; dy < scale; ++dy)
          for (int dx = 0; dx < scale; ++dx) map.at((c * a.width + x) * scale + dx, y * scale + dy) = colour;
      }
    }
  return map;
}

double maxRelativeDifference(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) return INFINITY;
  float peak = 0.0f;
  for (const glm::vec3& p : b.pixels) peak = std::max({peak, p.r, p.g, p.b});
  double worst = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double ref = b.pixels[i][c];
      const double d = std::abs(double(a.pixels[i][c]) - ref) / std::max(std::abs(ref), 1e-6 * peak);
      worst = std::max(worst, std::isfinite(d) ? d : INFINITY);
    }
  return worst;
}

namespace {

/// Least squares for a few unknowns: solves the normal equations A x = b (k×k, row-major)
/// by Gaussian elimination with partial pivoting; false when A is singular.
bool solveNormalEquations(std::vector<double> a, std::vector<double> b, std::vector<double>& x) {
  const std::size_t k = b.size();
  for (std::size_t col = 0; col < k; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < k; ++r)
      if (std::abs(a[r * k + col]) > std::abs(a[pivot * k + col])) pivot = r;
    if (!(std::abs(a[pivot * k + col]) > 1e-12 * std::abs(a[0]))) return false;
    for (std::size_t c = 0; c < k; ++c) std::swap(a[col * k + c], a[pivot * k + c]);
    std::swap(b[col], b[pivot]);
    for (std::size_t r = col + 1; r < k; ++r) {
      const double f = a[r * k + col] / a[col * k + col];
      for (std::size_t c = col; c < k; ++c) a[r * k + c] -= f * a[col * k + c];
      b[r] -= f * b[col];
    }
  }
  x.assign(k, 0.0);
  for (std::size_t r = k; r-- > 0;) {
    double sum = b[r];
    for (std::size_t c = r + 1; c < k; ++c) sum -= a[r * k + c] * x[c];
    x[r] = sum / a[r * k + r];
  }
  return true;
}

constexpr std::size_t kFitTerms = 6;  ///< 1, u, v, u², uv, v²

std::array<double, kFitTerms> quadraticTerms(double u, double v) { return {1.0, u, v, u * u, u * v, v * v}; }

/// Per phase bin: pixels and their summed relative variance.
struct PhaseBin {
  std::size_t count = 0;
  double variance = 0.0;
};

}  // namespace

GridBandAmplitude gridBandAmplitude(const Image& image, const std::vector<GridBandSample>& samples,
                                    const Image* standardError) {
  const int width = image.width, height = image.height;
  const std::size_t pixelCount = std::size_t(width) * std::size_t(height);
  if (standardError) requireSameSize(image, *standardError, "gridBandAmplitude");
  // Patches of similar normal: a cube's faces, a sphere's caps. One smooth fit per patch
  // follows its lighting; a fit across an edge would not.
  constexpr double kSamePatch = 0.9;
  constexpr std::size_t kNone = std::size_t(-1);
  std::vector<int> patchOf(pixelCount, -1);
  std::vector<std::size_t> sampleOf(pixelCount, kNone);
  std::vector<glm::dvec3> seeds;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const GridBandSample& s = samples[k];
    if (s.pixel >= pixelCount) throw std::invalid_argument("gridBandAmplitude: a sample's pixel is outside the image");
    if (!(luminance(image.pixels[s.pixel]) > 0.0)) continue;  // unlit (or not finite): nothing to fit
    int patch = -1;
    for (std::size_t j = 0; j < seeds.size() && patch < 0; ++j)
      if (glm::dot(seeds[j], s.normal) >= kSamePatch) patch = int(j);
    if (patch < 0) {
      patch = int(seeds.size());
      seeds.push_back(s.normal);
    }
    patchOf[s.pixel] = patch;
    sampleOf[s.pixel] = k;
  }
  // Each patch without its rim.
  std::vector<std::vector<std::size_t>> members(seeds.size());
  for (int y = kGridBandRim; y < height - kGridBandRim; ++y)
    for (int x = kGridBandRim; x < width - kGridBandRim; ++x) {
      const std::size_t at = std::size_t(y) * std::size_t(width) + std::size_t(x);
      const int patch = patchOf[at];
      if (patch < 0) continue;
      bool interior = true;
      for (int dy = -kGridBandRim; dy <= kGridBandRim && interior; ++dy)
        for (int dx = -kGridBandRim; dx <= kGridBandRim && interior; ++dx)
          interior = patchOf[std::size_t(y + dy) * std::size_t(width) + std::size_t(x + dx)] == patch;
      if (interior) members[std::size_t(patch)].push_back(sampleOf[at]);
    }
  // Every pixel that takes part: its patch, its fit terms, log-luminance and relative variance.
  struct Member {
    std::size_t sample = 0, patch = 0;
    std::array<double, kFitTerms> terms{};
    double logY = 0.0, variance = 0.0;
  };
  std::vector<Member> used;
  std::size_t patches = 0;
  for (const std::vector<std::size_t>& patch : members) {
    if (patch.size() < 64) continue;
    glm::dvec3 normal(0.0), centre(0.0);
    for (std::size_t k : patch) {
      normal += samples[k].normal;
      centre += samples[k].position;
    }
    normal = glm::normalize(normal);
    centre /= double(patch.size());
    const glm::dvec3 t1 =
        glm::normalize(glm::cross(normal, std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 t2 = glm::cross(normal, t1);
    double extent = 0.0;
    for (std::size_t k : patch)
      extent = std::max({extent, std::abs(glm::dot(samples[k].position - centre, t1)),
                         std::abs(glm::dot(samples[k].position - centre, t2))});
    if (!(extent > 0.0)) continue;
    for (std::size_t k : patch) {
      const GridBandSample& s = samples[k];
      const glm::dvec3 d = s.position - centre;
      Member m;
      m.sample = k;
      m.patch = patches;
      m.terms = quadraticTerms(glm::dot(d, t1) / extent, glm::dot(d, t2) / extent);
      const double y = luminance(image.pixels[s.pixel]);
      m.logY = std::log(y);
      if (standardError) {
        // Channels traced independently: the luminance's variance is the weighted sum.
        const glm::dvec3 se(standardError->pixels[s.pixel]);
        m.variance =
            (0.2126 * 0.2126 * se.x * se.x + 0.7152 * 0.7152 * se.y * se.y + 0.0722 * 0.0722 * se.z * se.z) / (y * y);
      }
      used.push_back(m);
    }
    ++patches;
  }
  GridBandAmplitude out;
  out.pixels = used.size();
  if (used.empty()) return out;
  const double n = double(used.size());
  // Per axis one joint least-squares fit of log-luminance: a quadratic per patch (the
  // smooth lighting) plus one offset per phase bin (the bands). Fitted jointly, a patch's
  // trend cannot take up bands that cross it only a few times, nor the bands its trend.
  // A tiny ridge on the offsets settles what no pixel decides (a phase seen by one flat,
  // grid-aligned patch only) at zero.
  const std::size_t unknowns = kFitTerms * patches + std::size_t(kGridBandBins);
  const std::size_t firstBin = kFitTerms * patches;
  for (int a = 0; a < 3; ++a) {
    std::vector<std::size_t> binOf(used.size());
    std::vector<double> ata(unknowns * unknowns, 0.0), atb(unknowns, 0.0), solution;
    std::array<PhaseBin, kGridBandBins> bins{};
    for (std::size_t i = 0; i < used.size(); ++i) {
      const Member& m = used[i];
      const GridBandSample& s = samples[m.sample];
      // Within a cell: the depth below the face the outward normal points through, so that
      // opposite faces (and both sides of a sphere) put the same phase in the same bin;
      // across cells: the layer's parity as it is (a reflected phase would swap odd and
      // even layers between opposite faces).
      const double layer = std::floor(s.grid[a]), within = s.grid[a] - layer;
      const double parity = layer - 2.0 * std::floor(0.5 * layer);
      const double phase = (parity + (s.normal[a] > 0.0 ? 1.0 - within : within)) / kGridBandPeriod;
      binOf[i] = std::size_t(std::clamp(int(phase * kGridBandBins), 0, kGridBandBins - 1));
      PhaseBin& bin = bins[binOf[i]];
      ++bin.count;
      bin.variance += m.variance;
      std::array<std::size_t, kFitTerms + 1> at{};
      std::array<double, kFitTerms + 1> value{};
      for (std::size_t t = 0; t < kFitTerms; ++t) {
        at[t] = kFitTerms * m.patch + t;
        value[t] = m.terms[t];
      }
      at[kFitTerms] = firstBin + binOf[i];
      value[kFitTerms] = 1.0;
      for (std::size_t r = 0; r <= kFitTerms; ++r) {
        atb[at[r]] += value[r] * m.logY;
        for (std::size_t c = 0; c <= kFitTerms; ++c) ata[at[r] * unknowns + at[c]] += value[r] * value[c];
      }
    }
    for (int b = 0; b < kGridBandBins; ++b) ata[(firstBin + std::size_t(b)) * (unknowns + 1)] += 1e-3;
    if (!solveNormalEquations(ata, atb, solution)) continue;
    double mean = 0.0;
    for (int b = 0; b < kGridBandBins; ++b) mean += double(bins[std::size_t(b)].count) * solution[firstBin + std::size_t(b)];
    mean /= n;
    double spread = 0.0, noise = 0.0;
    for (int b = 0; b < kGridBandBins; ++b) {
      const PhaseBin& bin = bins[std::size_t(b)];
      if (bin.count == 0) continue;
      const double offset = std::exp(solution[firstBin + std::size_t(b)] - mean) - 1.0;
      spread += double(bin.count) * offset * offset;
      noise += bin.variance / double(bin.count);
    }
    out.axis[a] = std::sqrt(spread / n);
    out.noise[a] = std::sqrt(noise / n);
  }
  out.amplitude = std::max({out.axis.x, out.axis.y, out.axis.z});
  return out;
}

}  // namespace sslpv

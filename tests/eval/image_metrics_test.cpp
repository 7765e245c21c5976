// The compare metrics (volume/eval/image_metrics.h) on synthetic images whose answers are
// known in closed form: identical images give zero error and SSIM 1, a uniform 10 %
// gain gives a mean relative error of exactly 0.1, the 1 % floor of the relative metrics
// acts only below 1 % of the mean reference, block averaging cancels checkerboard noise
// by the exact fraction of unpaired pixels, and SSIM matches a hand computation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "seeded_draws.h"
#include "volume/eval/image_metrics.h"

namespace sslpv {
namespace {

Image constantImage(int w, int h, glm::vec3 value) {
  Image image(w, h);
  for (glm::vec3& p : image.pixels) p = value;
  return image;
}

PixelMask fullMask(int w, int h) {
  PixelMask mask(w, h);
  for (auto& v : mask.inside) v = 1;
  return mask;
}

/// A smooth, strictly positive, coloured image: a "render" with structure for SSIM.
Image rampImage(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float s = 0.2f + 0.8f * float(x + 2 * y) / float(w + 2 * h);
      image.at(x, y) = glm::vec3(s, 0.7f * s, 0.3f * s + 0.05f);
    }
  return image;
}

TEST(ImageMetrics, IdenticalImagesHaveNoErrorAndSsimOne) {
  const Image b = rampImage(24, 20);
  const ImageMetrics m = computeImageMetrics(b, b, fullMask(24, 20));
  EXPECT_EQ(m.maskPixels, 24u * 20u);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.relativeMse, 0.0);
  EXPECT_EQ(m.meanRelativeError, 0.0);
  EXPECT_DOUBLE_EQ(m.meanRatio, 1.0);
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(ImageMetrics, TenPercentGainGivesExactRelativeErrors) {
  // B constant 2 (per channel 2, 3, 4: mean 3): every |B| ≥ 0.01 mean_B, so the mean
  // relative error is exactly 0.1, and (A−B)²/(B²+ε) = 0.01 B²/(B² + (0.03)²) per channel.
  const glm::vec3 bValue(2.0f, 3.0f, 4.0f);
  const Image b = constantImage(8, 6, bValue);
  const Image a = constantImage(8, 6, 1.1f * bValue);
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(8, 6));
  const double meanB = 3.0, eps = (0.01 * meanB) * (0.01 * meanB);
  EXPECT_DOUBLE_EQ(m.meanB, meanB);
  EXPECT_DOUBLE_EQ(m.relativeMseEpsilon, eps);
  EXPECT_NEAR(m.meanRelativeError, 0.1, 1e-6);  // float storage of 1.1 * B
  double expectedRelMse = 0.0, expectedSquared = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double bc = bValue[c], ac = double(1.1f * bValue[c]);
    expectedRelMse += (ac - bc) * (ac - bc) / (bc * bc + eps) / 3.0;
    expectedSquared += (ac - bc) * (ac - bc) / 3.0;
  }
  EXPECT_NEAR(m.relativeMse, expectedRelMse, 1e-12);
  // ≈ 0.01 / (1 + ε/B²): just below 0.01, the ε term is visible.
  EXPECT_LT(m.relativeMse, 0.01);
  EXPECT_GT(m.relativeMse, 0.01 * (1.0 - 3e-4));
  EXPECT_NEAR(m.rmse, std::sqrt(expectedSquared), 1e-12);
  EXPECT_NEAR(m.meanRatio, 1.1, 1e-6);
}

TEST(ImageMetrics, PerChannelRelativeErrorsAverageToTheMetric) {
  // Only green is 20 % bright and only blue 10 % dark: the channels' errors are exactly
  // those, red none, and the overall metric is their mean.
  const glm::vec3 bValue(2.0f, 3.0f, 4.0f);
  const Image b = constantImage(6, 5, bValue);
  const Image a = constantImage(6, 5, glm::vec3(2.0f, 3.6f, 3.6f));
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(6, 5));
  EXPECT_EQ(m.meanRelativeErrorRgb.r, 0.0);
  EXPECT_NEAR(m.meanRelativeErrorRgb.g, 0.2, 1e-6);
  EXPECT_NEAR(m.meanRelativeErrorRgb.b, 0.1, 1e-6);
  EXPECT_NEAR(m.meanRelativeError, 0.1, 1e-6);
}

TEST(ImageMetrics, RatioMapColoursEachChannelByItsRatio) {
  // 2 x 1 pixels: the left one A = B in red, twice B in green, half B in blue; the right
  // one outside the mask. Panels R, G, B side by side, each pixel drawn 2 x 2.
  Image b = constantImage(2, 1, glm::vec3(1.0f));
  Image a = b;
  a.at(0, 0) = glm::vec3(1.0f, 2.0f, 0.5f);
  PixelMask mask(2, 1);
  mask.set(0, 0, true);
  const Image map = ratioMap(a, b, mask, 0.01, 2);
  ASSERT_EQ(map.width, 3 * 2 * 2);
  ASSERT_EQ(map.height, 2);
  const glm::vec3 white(1.0f), red(1.0f, 0.0f, 0.0f), blue(0.0f, 0.0f, 1.0f), black(0.0f);
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      EXPECT_EQ(map.at(dx, dy), white);      // red panel: equal
      EXPECT_EQ(map.at(4 + dx, dy), red);    // green panel: x2, full red
      EXPECT_EQ(map.at(8 + dx, dy), blue);   // blue panel: x1/2, full blue
      EXPECT_EQ(map.at(2 + dx, dy), black);  // outside the mask
    }
  // x sqrt(2) is half way to red; both under the floor is grey, not "equal".
  a.at(0, 0) = glm::vec3(std::sqrt(2.0f), 0.001f, 0.002f);
  b.at(0, 0) = glm::vec3(1.0f, 0.002f, 0.001f);
  const Image second = ratioMap(a, b, mask, 0.01, 1);
  EXPECT_NEAR(second.at(0, 0).g, 0.5f, 1e-6f);
  EXPECT_EQ(second.at(0, 0).r, 1.0f);
  EXPECT_EQ(second.at(2, 0), glm::vec3(kRatioMapBelowFloor));
  EXPECT_EQ(second.at(4, 0), glm::vec3(kRatioMapBelowFloor));
  EXPECT_THROW(ratioMap(a, rampImage(3, 1), mask, 0.01, 1), std::invalid_argument);
  EXPECT_THROW(ratioMap(a, b, mask, 0.0, 1), std::invalid_argument);
}

TEST(ImageMetrics, ConstantOffsetGivesThatRmse) {
  const Image b = rampImage(16, 16);
  Image a = b;
  for (glm::vec3& p : a.pixels) p += glm::vec3(0.25f);
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(16, 16));
  EXPECT_NEAR(m.rmse, 0.25, 1e-6);
  EXPECT_NEAR(m.meanA - m.meanB, 0.25, 1e-6);
}

TEST(ImageMetrics, FloorOnlyActsBelowOnePercentOfTheMeanReference) {
  // Two pixels, grey: B = 1 and B = 0 (a black reference pixel), A = 1 and 0.5.
  // mean_B = 0.5, floor = 0.005, ε = 2.5e-5. Pixel 1: no error. Pixel 2: relative error
  // 0.5 / 0.005 = 100, squared 0.25 / 2.5e-5 = 1e4. Means over 2 pixels: 50 and 5000.
  Image a(2, 1), b(2, 1);
  a.at(0, 0) = glm::vec3(1.0f);
  b.at(0, 0) = glm::vec3(1.0f);
  a.at(1, 0) = glm::vec3(0.5f);
  b.at(1, 0) = glm::vec3(0.0f);
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(2, 1));
  EXPECT_DOUBLE_EQ(m.relativeFloor, 0.005);
  EXPECT_NEAR(m.meanRelativeError, 50.0, 1e-9);
  EXPECT_NEAR(m.relativeMse, 5000.0, 1e-6);
}

TEST(ImageMetrics, RelativeMetricsDoNotDependOnExposure) {
  // The floor scales with B, so scaling both images changes only RMSE (by the factor).
  const Image b = rampImage(20, 20);
  Image a = b;
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  for (glm::vec3& p : a.pixels) p *= test::drawVec3<glm::vec3>([&] { return 1.0f + noise(rng); });
  Image a1000 = a, b1000 = b;
  for (glm::vec3& p : a1000.pixels) p *= 1024.0f;  // a power of two: exact in float
  for (glm::vec3& p : b1000.pixels) p *= 1024.0f;
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(20, 20));
  const ImageMetrics s = computeImageMetrics(a1000, b1000, fullMask(20, 20));
  EXPECT_NEAR(s.relativeMse, m.relativeMse, 1e-12 * m.relativeMse);
  EXPECT_NEAR(s.meanRelativeError, m.meanRelativeError, 1e-12 * m.meanRelativeError);
  EXPECT_NEAR(s.ssim, m.ssim, 1e-9);
  EXPECT_NEAR(s.rmse, 1024.0 * m.rmse, 1e-9 * s.rmse);
}

TEST(ImageMetrics, MaskRestrictsEveryMetric) {
  // A differs from B only outside the mask: no error inside it.
  const Image b = rampImage(12, 12);
  Image a = b;
  PixelMask mask(12, 12);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      mask.set(x, y, x < 6);
      if (x >= 6) a.at(x, y) *= 3.0f;
    }
  const ImageMetrics m = computeImageMetrics(a, b, mask);
  EXPECT_EQ(m.maskPixels, 72u);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.meanRelativeError, 0.0);
  // SSIM windows reach across the mask edge (structure there differs), so below 1.
  EXPECT_LT(m.ssim, 1.0);
}

TEST(ImageMetrics, AutoMaskIsWhereEitherImageIsNonZero) {
  Image a(3, 2), b(3, 2);
  a.at(0, 0) = glm::vec3(0.0f, 0.0f, 1e-30f);
  b.at(2, 1) = glm::vec3(1.0f, 0.0f, 0.0f);
  a.at(1, 1) = glm::vec3(-1.0f, 0.0f, 0.0f);  // non-zero counts, whatever the sign
  const PixelMask m = autoMask(a, b);
  EXPECT_EQ(m.count(), 3u);
  EXPECT_TRUE(m.at(0, 0));
  EXPECT_TRUE(m.at(2, 1));
  EXPECT_TRUE(m.at(1, 1));
  EXPECT_FALSE(m.at(1, 0));
}

TEST(ImageMetrics, MaskImageIsWherePositive) {
  Image image(2, 2);
  image.at(0, 0) = glm::vec3(0.0f, 0.5f, 0.0f);
  image.at(1, 0) = glm::vec3(-1.0f);
  image.at(1, 1) = glm::vec3(1.0f);
  const PixelMask m = maskFromImage(image);
  EXPECT_EQ(m.count(), 2u);
  EXPECT_TRUE(m.at(0, 0));
  EXPECT_TRUE(m.at(1, 1));
}

TEST(ImageMetrics, BlockAveragingCancelsCheckerboardNoise) {
  // B = 1, A = 1 ± δ in a checkerboard: per pixel relative error δ. A 2×2 block holds two
  // of each sign (error 0); a 3×3 block holds 5 of one sign and 4 of the other, so its
  // average is 1 ± δ/9: the mean relative error drops from δ to δ/9, rMSE from ≈ δ² to
  // ≈ δ²/81, RMSE from δ to δ/9.
  const double delta = 0.2;
  const int w = 36, h = 36;  // divisible by 2 and 3
  const Image b = constantImage(w, h, glm::vec3(1.0f));
  Image a(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) a.at(x, y) = glm::vec3(float(1.0 + ((x + y) % 2 ? delta : -delta)));
  const ImageMetrics full = computeImageMetrics(a, b, fullMask(w, h));
  EXPECT_NEAR(full.meanRelativeError, delta, 1e-6);
  EXPECT_NEAR(full.rmse, delta, 1e-6);

  const ImageMetrics k2 = computeImageMetrics(blockAverage(a, 2), blockAverage(b, 2), blockMask(fullMask(w, h), 2));
  EXPECT_EQ(k2.maskPixels, 18u * 18u);
  EXPECT_NEAR(k2.meanRelativeError, 0.0, 1e-6);

  const ImageMetrics k3 = computeImageMetrics(blockAverage(a, 3), blockAverage(b, 3), blockMask(fullMask(w, h), 3));
  EXPECT_EQ(k3.maskPixels, 12u * 12u);
  EXPECT_NEAR(k3.meanRelativeError, delta / 9.0, 1e-6);
  EXPECT_NEAR(k3.rmse, delta / 9.0, 1e-6);
  const double eps = 1e-4;  // (0.01 mean_B)², mean_B = 1
  EXPECT_NEAR(k3.relativeMse, (delta / 9.0) * (delta / 9.0) / (1.0 + eps), 1e-7);
}

TEST(ImageMetrics, BlockSizesDropIncompleteEdgeBlocks) {
  Image image(7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) image.at(x, y) = glm::vec3(float(x + 10 * y));
  const Image blocks = blockAverage(image, 2);
  ASSERT_EQ(blocks.width, 3);
  ASSERT_EQ(blocks.height, 2);
  // Block (1, 1) averages x 2..3, y 2..3: values 22, 23, 32, 33.
  EXPECT_FLOAT_EQ(blocks.at(1, 1).r, 27.5f);
  EXPECT_THROW(blockAverage(image, 6), std::invalid_argument);
  EXPECT_THROW(blockAverage(image, 0), std::invalid_argument);
  EXPECT_EQ(blockAverage(image, 5).width, 1);
}

TEST(ImageMetrics, BlockMaskNeedsEveryPixelOfTheBlock) {
  PixelMask mask = fullMask(4, 4);
  mask.set(3, 3, false);  // spoils block (1, 1) only
  const PixelMask blocks = blockMask(mask, 2);
  EXPECT_EQ(blocks.count(), 3u);
  EXPECT_FALSE(blocks.at(1, 1));
}

TEST(ImageMetrics, SsimOfOnePixelIsTheLuminanceTerm) {
  // One pixel: means are the values, variances 0, so SSIM = (2 μa μb + C1)/(μa² + μb² + C1)
  // with L = max reference luminance = 2, C1 = (0.02)² = 4e-4. Luminance weights sum to 1.
  const Image a = constantImage(1, 1, glm::vec3(1.0f));
  const Image b = constantImage(1, 1, glm::vec3(2.0f));
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(1, 1));
  EXPECT_DOUBLE_EQ(m.ssimRange, 2.0);
  EXPECT_NEAR(m.ssim, (4.0 + 4e-4) / (5.0 + 4e-4), 1e-12);  // 0.80000
}

TEST(ImageMetrics, SsimOfTwoPixelsMatchesHandComputation) {
  // 2×1 images, grey: A = (0, 1), B = (1, 3). At either centre the window holds both
  // pixels with weights 1 and g = exp(−1/(2·1.5²)) ≈ 0.8007, renormalised: the centre
  // pixel weighs 1/(1+g), the other g/(1+g). L = 3: C1 = 9e-4, C2 = 8.1e-3.
  Image a(2, 1), b(2, 1);
  a.at(0, 0) = glm::vec3(0.0f);
  a.at(1, 0) = glm::vec3(1.0f);
  b.at(0, 0) = glm::vec3(1.0f);
  b.at(1, 0) = glm::vec3(3.0f);
  const double g = std::exp(-1.0 / 4.5), c1 = 9e-4, c2 = 8.1e-3;
  const double xa[2] = {0.0, 1.0}, xb[2] = {1.0, 3.0};
  double perCentre[2] = {0.0, 0.0};
  for (int centre = 0; centre < 2; ++centre) {
    const double w[2] = {centre == 0 ? 1.0 / (1.0 + g) : g / (1.0 + g), centre == 1 ? 1.0 / (1.0 + g) : g / (1.0 + g)};
    const double ma = w[0] * xa[0] + w[1] * xa[1], mb = w[0] * xb[0] + w[1] * xb[1];
    double va = 0, vb = 0, cov = 0;
    for (int i = 0; i < 2; ++i) {
      va += w[i] * (xa[i] - ma) * (xa[i] - ma);
      vb += w[i] * (xb[i] - mb) * (xb[i] - mb);
      cov += w[i] * (xa[i] - ma) * (xb[i] - mb);
    }
    perCentre[centre] = (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
  }
  const double expected = 0.5 * (perCentre[0] + perCentre[1]);
  EXPECT_NEAR(ssim(a, b, fullMask(2, 1), 3.0), expected, 1e-12);
  EXPECT_NEAR(computeImageMetrics(a, b, fullMask(2, 1)).ssim, expected, 1e-12);
  // Only the masked centre counts.
  PixelMask first(2, 1);
  first.set(0, 0, true);
  EXPECT_NEAR(ssim(a, b, first, 3.0), perCentre[0], 1e-12);
  EXPECT_GT(std::abs(perCentre[0] - perCentre[1]), 1e-3);  // so the line above can fail
}

TEST(ImageMetrics, SsimDecreasesWithNoise) {
  const Image b = rampImage(48, 48);
  double previous = 1.0;
  for (float sigma : {0.01f, 0.05f, 0.2f}) {
    Image a = b;
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, sigma);
    for (glm::vec3& p : a.pixels) p += glm::vec3(noise(rng));
    const double s = computeImageMetrics(a, b, fullMask(48, 48)).ssim;
    EXPECT_LT(s, previous) << "sigma " << sigma;
    previous = s;
  }
  EXPECT_LT(previous, 0.5);  // σ 0.2 on values of 0.2..1 destroys the structure
}

TEST(ImageMetrics, RejectsBrokenPreconditions) {
  const Image b = rampImage(4, 4);
  EXPECT_THROW(computeImageMetrics(rampImage(4, 5), b, fullMask(4, 4)), std::invalid_argument);
  EXPECT_THROW(computeImageMetrics(b, b, PixelMask(4, 4)), std::invalid_argument);
  Image nan = b;
  nan.at(2, 3).g = std::nanf("");
  EXPECT_THROW(computeImageMetrics(nan, b, fullMask(4, 4)), std::invalid_argument);
  ASSERT_TRUE(firstNonFinitePixel(nan).has_value());
  EXPECT_EQ(*firstNonFinitePixel(nan), glm::ivec2(2, 3));
  EXPECT_FALSE(firstNonFinitePixel(b).has_value());
  EXPECT_THROW(computeImageMetrics(b, constantImage(4, 4, glm::vec3(0.0f)), fullMask(4, 4)), std::invalid_argument);
}

TEST(ImageMetrics, JsonRecordHoldsEveryNumber) {
  const Image b = constantImage(2, 2, glm::vec3(1.0f));
  const Image a = constantImage(2, 2, glm::vec3(1.5f));
  const ImageMetrics m = computeImageMetrics(a, b, fullMask(2, 2));
  const std::string text = compareJson({"a.exr", "b.exr", "auto", 4, 4, 2}, m);
  for (const char* key : {"\"a\"", "\"b\"", "\"mask\"", "\"block\"", "\"mask_pixels\"", "\"mean_ratio\"",
                          "\"rmse\"", "\"relative_mse\"", "\"mean_relative_error\"",
                          "\"mean_relative_error_rgb\"", "\"ssim\"", "\"ssim_range\""})
    EXPECT_NE(text.find(key), std::string::npos) << key;
  EXPECT_EQ(text.back(), '\n');
}

}  // namespace
}  // namespace sslpv

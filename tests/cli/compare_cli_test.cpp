// `sslpv compare A B` as a user runs it: the numbers of the table and the JSON record on
// images with closed-form answers, the --mask and --block rules, and every bad input
// exiting 2 with one "sslpv: error:" line naming the file while a pre-existing --json
// file stays byte-identical and no file appears.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "test_support.h"
#include "volume/core/image_io.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kPreexistingJson = "{\"left\": \"by an earlier run, must survive failures\"}\n";

/// 36×36, background exactly 0, the object a square [x0, x1) × [x0, x1) of `value`.
Image squareImage(int x0, int x1, glm::vec3 value, int size = 36) {
  Image image(size, size);
  for (int y = x0; y < x1; ++y)
    for (int x = x0; x < x1; ++x) image.at(x, y) = value;
  return image;
}

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override { writeText(jsonPath(), kPreexistingJson); }

  fs::path jsonPath() const { return dir_ / "out.json"; }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const Image& image) {
    writeImage(image, dir_ / name);
    return file(name);
  }

  RunResult run(std::vector<std::string> args) {
    filesBefore_ = listing();
    args.insert(args.begin(), "compare");
    return runSslpv(args);
  }

  /// Runs with --json out.json and parses the record.
  json runJson(std::vector<std::string> args) {
    args.push_back("--json");
    args.push_back(jsonPath().string());
    const RunResult r = run(args);
    EXPECT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_EQ(r.stderrText, "");
    EXPECT_EQ(listing(), filesBefore_) << "only out.json may change, and no temporary file may remain";
    return json::parse(readText(jsonPath()));
  }

  /// Runs a bad invocation with --json out.json and checks the failure contract.
  void expectRejected(std::vector<std::string> args, const std::vector<std::string>& needles) {
    args.push_back("--json");
    args.push_back(jsonPath().string());
    const RunResult r = run(args);
    expectOneLineError(r, needles);
    EXPECT_EQ(r.stdoutText, "") << "no table on failure";
    EXPECT_EQ(readText(jsonPath()), kPreexistingJson) << "the existing JSON file was modified";
    EXPECT_EQ(listing(), filesBefore_) << "files were created or removed";
  }

  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_.path())) names.insert(entry.path().filename().string());
    return names;
  }

  TempDir dir_;
  std::set<std::string> filesBefore_;
};

TEST_F(CompareCli, TenPercentGainOverTheObject) {
  // Object: 20×20 pixels of B = (2, 3, 4), A = 1.1 B; background 0 in both, which the
  // automatic mask leaves out. Mean relative error exactly 0.1 (every B ≥ 0.01 mean B),
  // rMSE = mean over channels of 0.01 B² / (B² + (0.03)²).
  const glm::vec3 bValue(2.0f, 3.0f, 4.0f);
  const std::string b = write("b.exr", squareImage(8, 28, bValue));
  const std::string a = write("a.pfm", squareImage(8, 28, 1.1f * bValue));
  const json j = runJson({a, b});
  EXPECT_EQ(j["a"], a);
  EXPECT_EQ(j["b"], b);
  EXPECT_EQ(j["mask"], "auto");
  EXPECT_EQ(j["block"], 1);
  EXPECT_EQ(j["width"], 36);
  EXPECT_EQ(j["metric_width"], 36);
  EXPECT_EQ(j["mask_pixels"], 400);
  EXPECT_NEAR(j["mean_b"].get<double>(), 3.0, 1e-12);
  EXPECT_NEAR(j["mean_ratio"].get<double>(), 1.1, 1e-6);
  EXPECT_NEAR(j["mean_relative_error"].get<double>(), 0.1, 1e-6);
  double relMse = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double d = double(1.1f * bValue[c]) - bValue[c];
    relMse += d * d / (double(bValue[c]) * bValue[c] + 9e-4) / 3.0;
  }
  EXPECT_NEAR(j["relative_mse"].get<double>(), relMse, 1e-12);
  EXPECT_NEAR(j["relative_mse_epsilon"].get<double>(), 9e-4, 1e-15);
  EXPECT_NEAR(j["relative_error_floor"].get<double>(), 0.03, 1e-15);
  // L is the largest reference luminance: 0.2126·2 + 0.7152·3 + 0.0722·4.
  EXPECT_NEAR(j["ssim_range"].get<double>(), 0.2126 * 2 + 0.7152 * 3 + 0.0722 * 4, 1e-9);
  EXPECT_GT(j["ssim"].get<double>(), 0.9);
  EXPECT_LT(j["ssim"].get<double>(), 1.0);
  ASSERT_EQ(j["mean_a_rgb"].size(), 3u);
  EXPECT_NEAR(j["mean_a_rgb"][2].get<double>(), 4.4, 1e-6);
}

TEST_F(CompareCli, TablePrintsTheSameNumbers) {
  const std::string b = write("b.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string a = write("a.exr", squareImage(8, 28, glm::vec3(1.25f)));
  const RunResult r = run({a, b});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_EQ(readText(jsonPath()), kPreexistingJson) << "no --json, no JSON written";
  for (const char* row : {"mean A / B     1.25", "RMSE           0.25", "mean rel. err  0.25",
                          "mask           auto: 400 of 1296 pixels", "SSIM", "relative MSE"})
    EXPECT_NE(r.stdoutText.find(row), std::string::npos) << "missing '" << row << "' in\n" << r.stdoutText;
}

TEST_F(CompareCli, IdenticalImagesAgreeExactly) {
  const std::string b = write("b.exr", squareImage(4, 30, glm::vec3(0.3f, 0.2f, 0.1f)));
  const json j = runJson({b, b});
  EXPECT_EQ(j["rmse"], 0.0);
  EXPECT_EQ(j["relative_mse"], 0.0);
  EXPECT_EQ(j["mean_relative_error"], 0.0);
  EXPECT_NEAR(j["ssim"].get<double>(), 1.0, 1e-12);
}

TEST_F(CompareCli, BlocksCountOnlyWhenEntirelyInsideTheObject) {
  // Object [4, 32)²: of the 3×3 blocks, those covering pixels 6..29 on each axis lie
  // entirely inside (blocks 2..9: 8 × 8 = 64); a majority rule would also take blocks 1
  // and 10. B = 1, A = 1 ± δ in a checkerboard: a 3×3 block averages to 1 ± δ/9.
  const double delta = 0.2;
  Image a = squareImage(4, 32, glm::vec3(1.0f));
  for (int y = 4; y < 32; ++y)
    for (int x = 4; x < 32; ++x) a.at(x, y) = glm::vec3(float(1.0 + ((x + y) % 2 ? delta : -delta)));
  const std::string pa = write("a.exr", a);
  const std::string pb = write("b.exr", squareImage(4, 32, glm::vec3(1.0f)));
  const json pixels = runJson({pa, pb});
  EXPECT_EQ(pixels["mask_pixels"], 28 * 28);
  EXPECT_NEAR(pixels["mean_relative_error"].get<double>(), delta, 1e-6);
  const json blocks = runJson({pa, pb, "--block", "3"});
  EXPECT_EQ(blocks["block"], 3);
  EXPECT_EQ(blocks["metric_width"], 12);
  EXPECT_EQ(blocks["mask_pixels"], 64);
  EXPECT_NEAR(blocks["mean_relative_error"].get<double>(), delta / 9.0, 1e-6);
  EXPECT_NEAR(blocks["rmse"].get<double>(), delta / 9.0, 1e-6);
}

TEST_F(CompareCli, MaskFileSelectsPixelsAboveZero) {
  // A is wrong only on the left half of the object; the mask keeps the right half.
  Image a = squareImage(8, 28, glm::vec3(1.0f));
  for (int y = 8; y < 28; ++y)
    for (int x = 8; x < 18; ++x) a.at(x, y) = glm::vec3(2.0f);
  Image mask(36, 36);
  for (int y = 8; y < 28; ++y)
    for (int x = 18; x < 28; ++x) mask.at(x, y) = glm::vec3(1.0f);
  const std::string pa = write("a.exr", a), pb = write("b.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string pm = write("mask.png", mask);  // masks may be PNG: only > 0 matters
  const json j = runJson({pa, pb, "--mask", pm});
  EXPECT_EQ(j["mask"], pm);
  EXPECT_EQ(j["mask_pixels"], 200);
  EXPECT_EQ(j["rmse"], 0.0);
  const json whole = runJson({pa, pb});
  EXPECT_NEAR(whole["rmse"].get<double>(), std::sqrt(0.5), 1e-6);  // half the pixels off by 1
}

TEST_F(CompareCli, RejectsImagesOfDifferentSizes) {
  const std::string a = write("a.exr", squareImage(4, 20, glm::vec3(1.0f), 36));
  const std::string b = write("b.exr", squareImage(4, 20, glm::vec3(1.0f), 32));
  expectRejected({a, b}, {"b.exr", "32x32", "36x36"});
}

TEST_F(CompareCli, RejectsNanNamingPixelAndFile) {
  Image a = squareImage(8, 28, glm::vec3(1.0f));
  a.at(5, 7).g = std::numeric_limits<float>::quiet_NaN();  // in the background, still an error
  const std::string pa = write("a.pfm", a), pb = write("b.exr", squareImage(8, 28, glm::vec3(1.0f)));
  expectRejected({pa, pb}, {"a.pfm", "x=5", "y=7", "NaN"});
}

TEST_F(CompareCli, RejectsInfinityInTheReference) {
  Image b = squareImage(8, 28, glm::vec3(1.0f));
  b.at(20, 11).b = std::numeric_limits<float>::infinity();
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f))), pb = write("b.exr", b);
  expectRejected({pa, pb}, {"b.exr", "x=20", "y=11", "infinite"});
}

TEST_F(CompareCli, RejectsUnreadableFiles) {
  const std::string good = write("good.exr", squareImage(8, 28, glm::vec3(1.0f)));
  expectRejected({file("missing.exr"), good}, {"missing.exr"});
  writeText(dir_ / "garbage.exr", "not an EXR at all");
  expectRejected({good, file("garbage.exr")}, {"garbage.exr"});
  writeText(dir_ / "short.pfm", "PF\n36 36\n-1.0\n0123");
  expectRejected({file("short.pfm"), good}, {"short.pfm"});
  expectRejected({good, good, "--mask", file("nomask.png")}, {"nomask.png"});
}

TEST_F(CompareCli, RefusesToneMappedPng) {
  const std::string png = write("a.png", squareImage(8, 28, glm::vec3(0.5f)));
  const std::string exr = write("b.exr", squareImage(8, 28, glm::vec3(0.5f)));
  expectRejected({png, exr}, {"a.png", "PNG", "linear"});
  expectRejected({exr, png}, {"a.png", "PNG"});
}

TEST_F(CompareCli, RejectsEmptyMasks) {
  const std::string zero = write("zero.exr", Image(36, 36));
  const std::string zero2 = write("zero2.exr", Image(36, 36));
  expectRejected({zero, zero2}, {"zero.exr", "zero2.exr", "empty"});
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string pb = write("b.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string emptyMask = write("empty_mask.pfm", Image(36, 36));
  expectRejected({pa, pb, "--mask", emptyMask}, {"empty_mask.pfm", "empty"});
  // Object 2×2 pixels, blocks 4×4: no block lies entirely inside.
  const std::string small = write("small.exr", squareImage(9, 11, glm::vec3(1.0f)));
  expectRejected({small, small, "--block", "4"}, {"small.exr", "--block"});
}

TEST_F(CompareCli, RejectsMaskOfAnotherSize) {
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string pm = write("mask.exr", squareImage(8, 28, glm::vec3(1.0f), 40));
  expectRejected({pa, pa, "--mask", pm}, {"mask.exr", "40x40"});
}

TEST_F(CompareCli, RejectsBadBlockSizes) {
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  expectRejected({pa, pa, "--block", "0"}, {"--block"});
  expectRejected({pa, pa, "--block", "-3"}, {"--block"});
  expectRejected({pa, pa, "--block", "37"}, {"--block", "a.exr", "36x36"});
  expectRejected({pa, pa, "--block", "two"}, {"--block"});
  // One block the size of the image is fine when the object fills the image.
  const std::string full = write("full.exr", squareImage(0, 36, glm::vec3(1.0f)));
  const RunResult one = run({full, full, "--block", "36"});
  EXPECT_EQ(one.exitCode, 0) << one.stderrText;
  EXPECT_NE(one.stdoutText.find("auto: 1 of 1 blocks"), std::string::npos) << one.stdoutText;
}

TEST_F(CompareCli, RejectsAReferenceThatIsZeroOverTheObject) {
  // A lights pixels the reference leaves black: relative errors have nothing to scale by.
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string pb = write("b.exr", Image(36, 36));
  expectRejected({pa, pb}, {"b.exr", "positive"});
}

TEST_F(CompareCli, RatioMapShowsWhereEachChannelDiffers) {
  // The object [8, 28)² is 10 % bright in green only; with 4×4 blocks the map holds three
  // 36-pixel-wide panels of whole blocks (36 / 4 = 9 blocks, drawn 4×4 each). Inside the
  // object red and blue are white, green is pink (log2 1.1 of the way to red), and the
  // background is black.
  const std::string b = write("b.exr", squareImage(8, 28, glm::vec3(1.0f)));
  const std::string a = write("a.exr", squareImage(8, 28, glm::vec3(1.0f, 1.1f, 1.0f)));
  const std::string mapPath = file("map.exr");
  const RunResult r = run({a, b, "--block", "4", "--ratio-map", mapPath});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_NE(r.stdoutText.find("RGB 0 0.1 0"), std::string::npos) << "per-channel errors in\n" << r.stdoutText;
  const Image map = readImage(mapPath);
  ASSERT_EQ(map.width, 3 * 36);
  ASSERT_EQ(map.height, 36);
  const float pink = 1.0f - float(std::log2(1.1f / 1.0f));
  EXPECT_EQ(map.at(16, 16), glm::vec3(1.0f));
  EXPECT_EQ(map.at(2 * 36 + 16, 16), glm::vec3(1.0f));
  EXPECT_NEAR(map.at(36 + 16, 16).r, 1.0f, 1e-6f);
  EXPECT_NEAR(map.at(36 + 16, 16).g, pink, 1e-4f);
  EXPECT_NEAR(map.at(36 + 16, 16).b, pink, 1e-4f);
  EXPECT_EQ(map.at(2, 2), glm::vec3(0.0f));
}

TEST_F(CompareCli, RejectsARatioMapItCannotWriteBeforeReading) {
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  expectRejected({pa, pa, "--ratio-map", file("map.txt")}, {"map.txt", ".png"});
  expectRejected({pa, pa, "--ratio-map", (dir_ / "no_such_dir" / "map.png").string()}, {"no_such_dir"});
}

TEST_F(CompareCli, RejectsAnUnwritableJsonPathBeforeReading) {
  const std::string pa = write("a.exr", squareImage(8, 28, glm::vec3(1.0f)));
  filesBefore_ = listing();
  const RunResult r =
      runSslpv({"compare", pa, pa, "--json", (dir_ / "no_such_dir" / "out.json").string()});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.stderrText.find("no_such_dir"), std::string::npos) << r.stderrText;
  EXPECT_EQ(listing(), filesBefore_);
}

}  // namespace
}  // namespace sslpv::test

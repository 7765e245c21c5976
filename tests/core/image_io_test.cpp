#include "volume/core/image_io.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "seeded_draws.h"
#include "test_support.h"
#include "volume/core/error.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using test::drawVec3;
using test::readText;
using test::TempDir;
using test::writeText;

/// A non-square image (catches transposed loops) of values a float format must keep
/// bit-exactly: negatives, large, tiny and non-representable-in-half values.
Image makeHdrImage(int width, int height, unsigned seed) {
  Image image(width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (auto& p : image.pixels) {
    const glm::vec3 u = drawVec3<glm::vec3>(unit, rng);
    p = glm::vec3(u.x * 1e4f, u.y * 1e-6f, u.z + 1.0f / 3.0f);
  }
  return image;
}

void expectIdentical(const Image& actual, const Image& expected) {
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);
  for (std::size_t i = 0; i < expected.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(actual.pixels[i][c], expected.pixels[i][c]) << "pixel " << i << " channel " << c;
}

/// Runs `body` and returns the InputError message it throws ("" when it throws nothing).
template <typename F>
std::string inputErrorOf(F body) {
  try {
    body();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string pfmHeader(const char* magic, int w, int h, const char* scale) {
  return std::string(magic) + "\n" + std::to_string(w) + " " + std::to_string(h) + "\n" + scale + "\n";
}

std::string floatBytes(float v, bool bigEndian) {
  char b[4];
  std::memcpy(b, &v, 4);
  std::uint32_t probe = 1;
  const bool hostLittle = *reinterpret_cast<unsigned char*>(&probe) == 1;
  if (bigEndian == hostLittle) std::swap(b[0], b[3]), std::swap(b[1], b[2]);
  return std::string(b, 4);
}

TEST(ImageIo, PfmRoundTripIsExact) {
  TempDir dir;
  const Image image = makeHdrImage(7, 5, 1);
  writeImage(image, dir / "a.pfm", 3.0f);  // exposure is for PNG only
  expectIdentical(readImage(dir / "a.pfm"), image);
}

TEST(ImageIo, ExrRoundTripIsExact) {
  TempDir dir;
  const Image image = makeHdrImage(9, 4, 2);
  writeImage(image, dir / "a.EXR");  // extension matching is case-insensitive
  expectIdentical(readImage(dir / "a.EXR"), image);
}

TEST(ImageIo, PngRoundTripWithinSrgbQuantization) {
  TempDir dir;
  Image image(6, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 6; ++x) image.at(x, y) = glm::vec3(x / 5.0f, y / 2.0f, 0.5f * (x + y) / 7.0f);
  writeImage(image, dir / "a.png");
  const Image back = readImage(dir / "a.png");
  ASSERT_EQ(back.width, 6);
  ASSERT_EQ(back.height, 3);
  // Half an 8-bit step of the sRGB curve is at most 0.5/255 * dL/dE(1) ~ 0.0045 in linear.
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.pixels[i][c], image.pixels[i][c], 0.0046f) << i;
  // Dark values keep their relative precision thanks to the sRGB curve (a linear 8-bit
  // encoding would round 0.001 to 0).
  Image dark(1, 1);
  dark.at(0, 0) = glm::vec3(0.001f, 0.01f, 0.1f);
  writeImage(dark, dir / "dark.png");
  EXPECT_NEAR(readImage(dir / "dark.png").at(0, 0).x, 0.001f, 0.00015f);
}

TEST(ImageIo, PngAppliesExposureThenClamps) {
  TempDir dir;
  Image image(3, 1);
  image.at(0, 0) = glm::vec3(0.25f);
  image.at(1, 0) = glm::vec3(7.0f);
  image.at(2, 0) = glm::vec3(-1.0f, NAN, 0.5f);
  writeImage(image, dir / "e.png", 2.0f);
  const Image back = readImage(dir / "e.png");
  EXPECT_NEAR(back.at(0, 0).x, 0.5f, 0.005f);
  EXPECT_EQ(back.at(1, 0), glm::vec3(1.0f));
  EXPECT_EQ(back.at(2, 0).x, 0.0f);
  EXPECT_EQ(back.at(2, 0).y, 0.0f);  // NaN becomes black rather than garbage
  EXPECT_EQ(back.at(2, 0).z, 1.0f);
}

TEST(ImageIo, PfmStoresBottomRowFirstAndReadsTopRowBack) {
  TempDir dir;
  Image image(2, 3);
  image.at(0, 0) = glm::vec3(1.0f, 0.0f, 0.0f);  // top-left red
  image.at(1, 2) = glm::vec3(0.0f, 0.0f, 4.0f);  // bottom-right blue
  writeImage(image, dir / "o.pfm");
  const std::string bytes = readText(dir / "o.pfm");
  const std::string header = "PF\n2 3\n-1.0\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 2 * 3 * 12);
  // Per the PFM spec the first stored row is the bottom one: its second pixel's blue.
  float firstRowBlue = 0.0f;
  std::memcpy(&firstRowBlue, bytes.data() + header.size() + 12 + 8, 4);
  EXPECT_EQ(firstRowBlue, 4.0f);
  const Image back = readImage(dir / "o.pfm");
  EXPECT_EQ(back.at(0, 0), glm::vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(back.at(1, 2), glm::vec3(0.0f, 0.0f, 4.0f));
}

TEST(ImageIo, PfmReadsBothEndiannessesAndGreyscale) {
  TempDir dir;
  // One pixel row per file, 2x1: values 1.5 and -2.25 (grey) or (1,2,3),(4,5,6) (RGB).
  for (bool big : {false, true}) {
    std::string grey = pfmHeader("Pf", 2, 1, big ? "1.0" : "-1.0");
    grey += floatBytes(1.5f, big) + floatBytes(-2.25f, big);
    writeText(dir / "g.pfm", grey);
    const Image g = readImage(dir / "g.pfm");
    ASSERT_EQ(g.width, 2);
    EXPECT_EQ(g.at(0, 0), glm::vec3(1.5f));
    EXPECT_EQ(g.at(1, 0), glm::vec3(-2.25f));

    std::string rgb = pfmHeader("PF", 2, 1, big ? "2.5" : "-0.5");  // |scale| is not a gain
    for (int v = 1; v <= 6; ++v) rgb += floatBytes(float(v), big);
    writeText(dir / "c.pfm", rgb);
    const Image c = readImage(dir / "c.pfm");
    EXPECT_EQ(c.at(0, 0), glm::vec3(1.0f, 2.0f, 3.0f)) << (big ? "big" : "little") << "-endian";
    EXPECT_EQ(c.at(1, 0), glm::vec3(4.0f, 5.0f, 6.0f));
  }
}

TEST(ImageIo, TruncatedOrMalformedPfmIsAnInputErrorNamingTheFile) {
  TempDir dir;
  writeImage(makeHdrImage(8, 8, 3), dir / "full.pfm");
  const std::string full = readText(dir / "full.pfm");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"truncated raster", full.substr(0, full.size() - 5)},
      {"header only", full.substr(0, 11)},
      {"empty", ""},
      {"wrong magic", "P6\n8 8\n255\n" + std::string(192, 'x')},
      {"negative size", pfmHeader("PF", -3, 2, "-1.0") + std::string(72, '\0')},
      {"huge size", pfmHeader("PF", 100000000, 100000000, "-1.0") + std::string(64, '\0')},
      {"size bigger than the file", pfmHeader("PF", 60000, 60000, "-1.0") + std::string(64, '\0')},
      {"zero scale", pfmHeader("PF", 1, 1, "0") + std::string(12, '\0')},
      {"text scale", pfmHeader("PF", 1, 1, "abc") + std::string(12, '\0')},
  };
  for (const auto& [what, content] : cases) {
    const fs::path file = dir / "bad.pfm";
    writeText(file, content);
    const std::string message = inputErrorOf([&] { readImage(file); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << what << ": '" << message << "'";
  }
}

TEST(ImageIo, GarbageOrTruncatedExrAndPngAreInputErrors) {
  TempDir dir;
  std::mt19937 rng(4);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = char(rng());
  writeText(dir / "g.exr", garbage);
  writeText(dir / "g.png", garbage);
  // A real EXR magic number followed by garbage gets past the first check.
  writeText(dir / "m.exr", std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8) + garbage);
  writeImage(makeHdrImage(64, 64, 5), dir / "full.exr");
  const std::string exr = readText(dir / "full.exr");
  writeText(dir / "t.exr", exr.substr(0, exr.size() / 2));
  writeImage(makeHdrImage(64, 64, 6), dir / "full.png");
  const std::string png = readText(dir / "full.png");
  writeText(dir / "t.png", png.substr(0, png.size() / 2));
  for (const char* name : {"g.exr", "g.png", "m.exr", "t.exr", "t.png"}) {
    const fs::path file = dir / name;
    const std::string message = inputErrorOf([&] { readImage(file); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << name << ": '" << message << "'";
    EXPECT_EQ(message.find('\n'), std::string::npos) << name << ": message is one line";
  }
}

TEST(ImageIo, MissingFileIsAnInputErrorNamingIt) {
  TempDir dir;
  const std::string message = inputErrorOf([&] { readImage(dir / "absent.exr"); });
  EXPECT_NE(message.find("absent.exr"), std::string::npos) << message;
}

TEST(ImageIo, UnknownExtensionNamesFileAndListsTheFormats) {
  TempDir dir;
  EXPECT_TRUE(isSupportedImageExtension("x.PNG"));
  EXPECT_TRUE(isSupportedImageExtension("dir/x.pfm"));
  EXPECT_FALSE(isSupportedImageExtension("x.jpg"));
  EXPECT_FALSE(isSupportedImageExtension("exr"));
  for (const fs::path& file : {dir / "out.jpg", dir / "out"}) {
    const std::string message = inputErrorOf([&] { writeImage(Image(2, 2), file); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    for (const char* ext : {".png", ".pfm", ".exr"}) EXPECT_NE(message.find(ext), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(file));
  }
  writeText(dir / "in.tiff", "data");
  EXPECT_NE(inputErrorOf([&] { readImage(dir / "in.tiff"); }).find("in.tiff"), std::string::npos);
}

TEST(ImageIo, WriteIntoMissingDirectoryFailsAndLeavesNothing) {
  TempDir dir;
  const fs::path target = dir / "no-such-dir" / "out.exr";
  const std::string message = inputErrorOf([&] { writeImage(Image(2, 2), target); });
  EXPECT_NE(message.find(target.string()), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(target.parent_path()));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(ImageIo, FailedWriteKeepsExistingTargetByteIdenticalAndLeavesNoTempFile) {
  // A file-size limit makes the write fail part-way, like a full disk. It runs in a
  // child process so the limit does not leak into other tests.
  for (const char* name : {"out.pfm", "out.exr", "out.png"}) {
    TempDir dir;
    const fs::path target = dir / name;
    const std::string original = "previous contents of the target, not an image";
    writeText(target, original);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      signal(SIGXFSZ, SIG_IGN);  // writes past the limit fail with EFBIG instead of killing
      const rlimit limit{4096, 4096};
      setrlimit(RLIMIT_FSIZE, &limit);
      Image big = makeHdrImage(300, 200, 7);  // far over 4 KiB in every format
      int code = 3;
      try {
        writeImage(big, target);
        code = 1;  // the write did not notice the failure
      } catch (const ResourceError& e) {
        // Not the user's input but the machine's limits: "FILE: write failed: <reason>".
        code = std::string(e.what()).find(target.string() + ": write failed: ") != std::string::npos ? 0 : 2;
      } catch (...) {
      }
      _exit(code);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << name << ": 1 = failure unnoticed, 2 = message without \"FILE: write failed: \", 3 = other exception";
    EXPECT_EQ(readText(target), original) << name;
    std::size_t entries = 0;
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      ++entries;
      EXPECT_EQ(entry.path(), target) << "left behind: " << entry.path();
    }
    EXPECT_EQ(entries, 1u);
  }
}

TEST(ImageIo, SuccessfulWriteReplacesExistingTarget) {
  TempDir dir;
  writeText(dir / "r.pfm", "old");
  const Image image = makeHdrImage(3, 2, 8);
  writeImage(image, dir / "r.pfm");
  expectIdentical(readImage(dir / "r.pfm"), image);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1u);  // no temporary file next to it
}

}  // namespace
}  // namespace sslpv

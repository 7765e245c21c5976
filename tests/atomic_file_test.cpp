// Atomic output files: a set of files replaced together or not at all, and temporaries
// removed when a signal ends the process in the middle of a write.
#include <gtest/gtest.h>

#include <cerrno>
#include <csignal>
#include <fstream>
#include <stdexcept>

#include "test_support.h"
#include "volume/atomic_file.h"
#include "volume/error.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using test::readText;
using test::TempDir;
using test::writeText;

std::function<void(const fs::path&)> writes(const std::string& text) {
  return [text](const fs::path& temp) { writeText(temp, text); };
}

std::size_t temporaries(const fs::path& dir) {
  std::size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    count += entry.path().filename().string().find(".tmp-") != std::string::npos;
  return count;
}

TEST(AtomicFile, TogetherReplacesEveryFileWhenEveryWriteSucceeds) {
  TempDir dir;
  writeText(dir / "a", "old a");
  writeAtomicallyTogether({{dir / "a", writes("new a")}, {dir / "b", writes("new b")}});
  EXPECT_EQ(readText(dir / "a"), "new a");
  EXPECT_EQ(readText(dir / "b"), "new b");
  EXPECT_EQ(temporaries(dir.path()), 0u);
}

TEST(AtomicFile, TogetherReplacesNothingWhenALaterWriteFails) {
  TempDir dir;
  writeText(dir / "image", "old image");
  writeText(dir / "error", "old error");
  const auto fails = [](const fs::path& temp) {
    writeText(temp, "half");
    throw ResourceError("error: write failed: No space left on device");
  };
  EXPECT_THROW(writeAtomicallyTogether({{dir / "image", writes("new image")}, {dir / "error", fails}}),
               ResourceError);
  EXPECT_EQ(readText(dir / "image"), "old image") << "replaced although its companion could not be written";
  EXPECT_EQ(readText(dir / "error"), "old error");
  EXPECT_EQ(temporaries(dir.path()), 0u);
}

TEST(AtomicFileDeathTest, SigtermDuringAWriteRemovesTheTemporaryAndEndsBySigterm) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  TempDir dir;
  writeText(dir / "out", "old");
  EXPECT_EXIT(
      {
        removeTemporariesOnSignals();
        writeAtomically(dir / "out", [](const fs::path& temp) {
          writeText(temp, "partial");
          std::raise(SIGTERM);
        });
      },
      ::testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(readText(dir / "out"), "old");
  EXPECT_EQ(temporaries(dir.path()), 0u) << "the killed writer's temporary is left behind";
}

TEST(AtomicFile, WriteFailureNamesTheFileAndTheSystemReason) {
  try {
    throwWriteFailed("/some/out.pfm", ENOSPC);
    FAIL() << "no exception";
  } catch (const ResourceError& e) {
    EXPECT_STREQ(e.what(), "/some/out.pfm: write failed: No space left on device");
  }
}

}  // namespace
}  // namespace sslpv

// Atomic output files: a set of files replaced together or not at all, and temporaries
// removed when a signal ends the process in the middle of a write.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <fstream>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

#include "test_support.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"

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

// A writer killed -9 leaves "<target>.tmp-<pid>-<n>", or when it wrote its temporary
// atomically in turn "<target>.tmp-<pid>-<n>.tmp-<pid>-<m>": both go once the pid is gone;
// a live process's temporary and names of another shape stay.
TEST(AtomicFile, StaleTemporariesOfGoneWritersAreRemovedNestedOnesToo) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child), alive = std::to_string(::getppid());
  TempDir dir;
  for (const std::string& name : {"out.tmp-" + dead + "-0", "out.tmp-" + dead + "-1.tmp-" + dead + "-2",
                                  "out.tmp-" + alive + "-3", "out.tmp-" + dead + "-4.tmp-" + alive + "-5",
                                  std::string("out.tmp-x-6")})
    writeText(dir / name, "partial");
  removeStaleTemporaries(dir / "out");
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir.path())) left.push_back(entry.path().filename().string());
  std::sort(left.begin(), left.end());
  std::vector<std::string> expected = {"out.tmp-" + alive + "-3", "out.tmp-" + dead + "-4.tmp-" + alive + "-5",
                                       "out.tmp-x-6"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(left, expected);
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

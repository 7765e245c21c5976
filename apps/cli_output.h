#pragma once
// What the writing subcommands tell the user besides errors: one "wrote" line per output
// on stdout, progress of long renders on stderr, and warnings on stderr.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

#include "volume/core/image_io.h"
#include "volume/scene/scene.h"

namespace sslpv {

using CliClock = std::chrono::steady_clock;

/// "wrote FILE (DETAIL, N ms)" on stdout, N counted from `start` (the command's start):
/// a silent success looks the same as a command that did nothing.
void printWrote(const std::string& file, const std::string& detail, CliClock::time_point start);

/// "WxH" of an image, the detail of printWrote for images.
std::string imageSizeText(const Image& image);

/// --size WxH (render, view): the image size instead of camera.width x camera.height (the
/// aspect, and with it the horizontal field of view, follows the new size). InputError
/// naming the flag on a malformed or out-of-range size.
void applySizeFlag(const std::string& size, Camera& camera);

/// "sslpv: warning: MESSAGE" on stderr, newlines flattened to keep it one line.
void printWarning(std::string message);

/// When every pixel is zero (or not above `1e-30`), a warning naming `what` (a scene or an
/// output): an all-black image is almost always a scene mistake, not the intended result.
/// The command still succeeds: the image is what the scene describes.
void warnIfBlack(const Image& image, const std::string& what);

/// Progress of a long render on stderr. On a terminal a line redrawn with carriage
/// returns; otherwise (a log file, a pipe, a job scheduler) nothing until finish(), so logs
/// hold one readable line instead of hundreds of overwritten ones.
class ProgressLine {
 public:
  /// `label` starts every line ("reference").
  explicit ProgressLine(std::string label);
  /// `terminal` forces the mode (tests); the default asks isatty(stderr).
  ProgressLine(std::string label, bool terminal);
  void update(std::size_t done, std::size_t total);
  /// Ends the progress with "LABEL: SUMMARY (N s)".
  void finish(const std::string& summary);

 private:
  std::string label_;
  bool terminal_;
  int lastPercent_ = -1;
  CliClock::time_point start_ = CliClock::now();
};

/// A wait whose length cannot be known (the first Vulkan frame compiles the device's
/// pipelines when Mesa's shader cache lacks them: 4 s on lavapipe, 0.9 s with the cache).
/// Once it has lasted `delay`, on a terminal, a line "LABEL ... N.N s" ticks until the
/// object is destroyed, which erases it. Nothing off a terminal (logs get the command's
/// own summary line) or for a shorter wait.
class WaitNotice {
 public:
  explicit WaitNotice(std::string label, std::chrono::milliseconds delay = std::chrono::seconds(1));
  /// `terminal` forces the mode and `out` the stream (tests); the default asks isatty(stderr).
  WaitNotice(std::string label, std::chrono::milliseconds delay, bool terminal, std::FILE* out);
  ~WaitNotice();
  WaitNotice(const WaitNotice&) = delete;
  WaitNotice& operator=(const WaitNotice&) = delete;

 private:
  void run(std::string label, std::chrono::milliseconds delay, std::FILE* out);

  std::mutex mutex_;
  std::condition_variable done_;
  bool finished_ = false;
  std::thread ticker_;
};

}  // namespace sslpv

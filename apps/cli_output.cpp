#include "apps/cli_output.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <utility>

#include "volume/core/error.h"

namespace sslpv {

void printWrote(const std::string& file, const std::string& detail, CliClock::time_point start) {
  const long long ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(CliClock::now() - start).count();
  std::printf("wrote %s (%s%s%lld ms)\n", file.c_str(), detail.c_str(), detail.empty() ? "" : ", ", ms);
  std::fflush(stdout);
}

std::string imageSizeText(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void applySizeFlag(const std::string& size, Camera& camera) {
  const std::string expected = "--size: expected WxH with whole numbers from 1 to " + std::to_string(kMaxImageSide) +
                               " (e.g. 640x480), got '" + size + "'";
  const std::size_t x = size.find_first_of("xX");
  if (x == std::string::npos || x == 0 || x + 1 == size.size()) throw InputError(expected);
  auto side = [&](const std::string& text) {
    if (text.size() > 6 || text.find_first_not_of("0123456789") != std::string::npos) throw InputError(expected);
    const int value = std::stoi(text);
    if (value < 1 || value > kMaxImageSide) throw InputError(expected);
    return value;
  };
  camera.width = side(size.substr(0, x));
  camera.height = side(size.substr(x + 1));
}

void printWarning(std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  std::cerr << "sslpv: warning: " << message << std::endl;
}

void warnIfBlack(const Image& image, const std::string& what) {
  // Far below anything a tone mapper or a float EXR reader would show as non-black.
  constexpr float kBlack = 1e-30f;
  for (const glm::vec3& p : image.pixels)
    if (p.r > kBlack || p.g > kBlack || p.b > kBlack) return;
  printWarning(what +
               ": the image is black (every pixel is zero): check that the camera and the lights are outside "
               "the object and face it, the light intensities, and transform.scale against the units");
}

ProgressLine::ProgressLine(std::string label) : ProgressLine(std::move(label), ::isatty(STDERR_FILENO) == 1) {}

ProgressLine::ProgressLine(std::string label, bool terminal) : label_(std::move(label)), terminal_(terminal) {}

void ProgressLine::update(std::size_t done, std::size_t total) {
  if (!terminal_ || total == 0) return;
  const int percent = int(100.0 * double(done) / double(total));
  if (percent == lastPercent_) return;
  lastPercent_ = percent;
  const double elapsed = std::chrono::duration<double>(CliClock::now() - start_).count();
  const double eta = done > 0 ? elapsed * double(total - done) / double(done) : 0.0;
  std::fprintf(stderr, "\r%s: %3d%%  %.1f s elapsed, ETA %.1f s   ", label_.c_str(), percent, elapsed, eta);
  std::fflush(stderr);
}

void ProgressLine::finish(const std::string& summary) {
  const double elapsed = std::chrono::duration<double>(CliClock::now() - start_).count();
  // On a terminal the summary replaces the progress line (padded over its tail).
  std::fprintf(stderr, "%s%s: %s (%.1f s)%s\n", terminal_ ? "\r" : "", label_.c_str(), summary.c_str(), elapsed,
               terminal_ ? "            " : "");
  std::fflush(stderr);
}

WaitNotice::WaitNotice(std::string label, std::chrono::milliseconds delay)
    : WaitNotice(std::move(label), delay, ::isatty(STDERR_FILENO) == 1, stderr) {}

WaitNotice::WaitNotice(std::string label, std::chrono::milliseconds delay, bool terminal, std::FILE* out) {
  if (terminal) ticker_ = std::thread([this, label = std::move(label), delay, out] { run(label, delay, out); });
}

WaitNotice::~WaitNotice() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
  }
  done_.notify_all();
  if (ticker_.joinable()) ticker_.join();
}

void WaitNotice::run(std::string label, std::chrono::milliseconds delay, std::FILE* out) {
  const auto start = CliClock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  if (done_.wait_for(lock, delay, [&] { return finished_; })) return;
  std::size_t width = 0;
  do {
    const double elapsed = std::chrono::duration<double>(CliClock::now() - start).count();
    const std::string line = label + " ... " + std::to_string(int(elapsed * 10.0) / 10) + "." +
                             std::to_string(int(elapsed * 10.0) % 10) + " s";
    width = std::max(width, line.size());
    std::fprintf(out, "\r%s", line.c_str());
    std::fflush(out);
  } while (!done_.wait_for(lock, std::chrono::milliseconds(250), [&] { return finished_; }));
  // Erased, so that what the command prints next starts on a clean line.
  std::fprintf(out, "\r%s\r", std::string(width, ' ').c_str());
  std::fflush(out);
}

}  // namespace sslpv

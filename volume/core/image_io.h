#pragma once
// Linear RGB float images and their files: PFM and EXR keep linear radiance; PNG is
// tone-mapped (exposure, clamp, sRGB). Every write is atomic.
#include <filesystem>
#include <glm/vec3.hpp>
#include <vector>

#include "volume/core/atomic_file.h"

namespace sslpv {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;  ///< row 0 is the top row
  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(std::size_t(w) * h, glm::vec3(0.0f)) {}
  glm::vec3& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
  const glm::vec3& at(int x, int y) const { return pixels[std::size_t(y) * width + x]; }
};

/// Format chosen by extension (.png, .pfm, .exr; case-insensitive). InputError for any
/// other extension or a missing/unwritable directory; the target is never half-written.
void writeImage(const Image& image, const std::filesystem::path& file, float exposure = 1.0f);

/// writeImage's checks and encoder as one file of writeAtomicallyTogether, for images
/// that must be replaced together; `image` must outlive the result.
AtomicOutput imageOutput(const Image& image, const std::filesystem::path& file, float exposure = 1.0f);

/// The PNG writer's display encoding (exposure, clamp to [0, 1], sRGB, 8 bits), RGB
/// interleaved, row 0 the top row: what a window shows of a rendered image.
std::vector<unsigned char> toDisplayRgb8(const Image& image, float exposure = 1.0f);

/// Writes bytes in toDisplayRgb8's layout (a window's frame, already display-encoded) as a
/// PNG, atomically; `file` must end in .png (InputError otherwise).
void writeDisplayPng(const std::vector<unsigned char>& rgb, int width, int height, const std::filesystem::path& file);

/// Reads .pfm or .exr (linear) or .png (converted back to linear). InputError when
/// unreadable, truncated or of another format.
Image readImage(const std::filesystem::path& file);

/// True when the extension is one writeImage accepts.
bool isSupportedImageExtension(const std::filesystem::path& file);

}  // namespace sslpv

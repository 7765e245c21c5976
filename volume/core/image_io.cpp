#include "volume/core/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/core/input_file.h"

namespace sslpv {
namespace fs = std::filesystem;
namespace {

enum class ImageFormat { Png, Pfm, Exr, Unknown };

// Larger images are certainly corrupt headers, not renders; refusing them up front keeps
// a garbage header from asking for gigabytes.
constexpr long long kMaxImageDimension = 1 << 16;
constexpr long long kMaxImagePixels = 1LL << 28;

ImageFormat formatOf(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".pfm") return ImageFormat::Pfm;
  if (ext == ".exr") return ImageFormat::Exr;
  return ImageFormat::Unknown;
}

/// Library messages may span lines; ours are one line.
std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

[[noreturn]] void failUnknownExtension(const fs::path& file) {
  throw InputError(file.string() + ": unsupported image extension '" +
                   file.extension().string() + "' (expected .png, .pfm or .exr)");
}

void requireSaneDimensions(const fs::path& file, long long width, long long height) {
  if (width <= 0 || height <= 0 || width > kMaxImageDimension || height > kMaxImageDimension ||
      width * height > kMaxImagePixels)
    throw InputError(file.string() + ": invalid image size " + std::to_string(width) + "x" +
                     std::to_string(height));
}

bool hostIsLittleEndian() {
  const std::uint32_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

float byteSwapped(float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  bits = (bits >> 24) | ((bits >> 8) & 0xff00u) | ((bits << 8) & 0xff0000u) | (bits << 24);
  std::memcpy(&value, &bits, 4);
  return value;
}

// sRGB transfer function (IEC 61966-2-1), applied per channel.
float linearToSrgb(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear
                              : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}
float srgbToLinear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

// ---- PFM: "PF" (RGB) or "Pf" (grey), width height, scale (< 0: little-endian), then
// float rows from the bottom of the image to the top.

// Writers write to `path` (the temporary file) and name `target` in their messages.
void writePfm(const Image& image, const fs::path& path, const fs::path& target) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(target.string() + ": cannot open for writing");
  out << "PF\n" << image.width << ' ' << image.height << '\n' << "-1.0\n";
  std::vector<float> row(std::size_t(image.width) * 3);
  const bool swap = !hostIsLittleEndian();
  for (int y = image.height - 1; y >= 0; --y) {
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = image.at(x, y)[c];
        row[std::size_t(x) * 3 + c] = swap ? byteSwapped(v) : v;
      }
    out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * 4));
  }
  out.close();
  if (!out) throwWriteFailed(target, errno);
}

std::string readWholeFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open image");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw InputError(file.string() + ": read failed");
  return content.str();
}

/// Parses the PFM header tokens strictly, never reading past the buffer.
class PfmHeaderReader {
 public:
  PfmHeaderReader(const std::string& data, const fs::path& file) : data_(data), file_(file) {}

  std::string token() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_])) &&
           pos_ - start < 32)
      ++pos_;
    if (start == pos_) fail("truncated header");
    return data_.substr(start, pos_ - start);
  }
  long long integer() {
    const std::string t = token();
    if (t.empty() || !std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
        t.size() > 9)
      fail("invalid image size '" + t + "'");
    return std::stoll(t);
  }
  double real() {
    const std::string t = token();
    try {
      std::size_t used = 0;
      const double v = std::stod(t, &used);
      if (used == t.size() && std::isfinite(v) && v != 0.0) return v;
    } catch (const std::exception&) {
    }
    fail("invalid scale '" + t + "'");
  }
  /// Exactly one whitespace character separates the header from the raster.
  std::size_t rasterStart() {
    if (pos_ >= data_.size() || !std::isspace(static_cast<unsigned char>(data_[pos_])))
      fail("truncated header");
    return pos_ + 1;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_.string() + ": not a valid PFM file: " + what);
  }

 private:
  const std::string& data_;
  const fs::path& file_;
  std::size_t pos_ = 0;
};

Image readPfm(const fs::path& file) {
  const std::string data = readWholeFile(file);
  PfmHeaderReader header(data, file);
  const std::string magic = header.token();
  int channels = 0;
  if (magic == "PF") channels = 3;
  else if (magic == "Pf") channels = 1;
  else header.fail("expected 'PF' or 'Pf' magic");
  const long long width = header.integer();
  const long long height = header.integer();
  requireSaneDimensions(file, width, height);
  const double scale = header.real();
  const std::size_t start = header.rasterStart();
  const std::size_t needed = std::size_t(width) * std::size_t(height) * channels * 4;
  if (data.size() - start < needed)
    throw InputError(file.string() + ": truncated PFM: " + std::to_string(width) + "x" +
                     std::to_string(height) + " needs " + std::to_string(needed) +
                     " bytes of pixels, file has " + std::to_string(data.size() - start));
  const bool swap = (scale < 0.0) != hostIsLittleEndian();
  Image image(static_cast<int>(width), static_cast<int>(height));
  const char* raster = data.data() + start;
  for (int row = 0; row < image.height; ++row) {
    const int y = image.height - 1 - row;  // first stored row is the bottom one
    for (int x = 0; x < image.width; ++x) {
      glm::vec3 pixel;
      for (int c = 0; c < 3; ++c) {
        const std::size_t sample = (std::size_t(row) * image.width + x) * channels +
                                   std::size_t(channels == 3 ? c : 0);
        float v = 0.0f;
        std::memcpy(&v, raster + sample * 4, 4);
        pixel[c] = swap ? byteSwapped(v) : v;
      }
      image.at(x, y) = pixel;
    }
  }
  return image;
}

// ---- OpenEXR: 32-bit float R, G, B so linear radiance round-trips exactly.

void writeExr(const Image& image, const fs::path& path, const fs::path& target) {
  Imf::Header header(image.width, image.height);
  for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  Imf::FrameBuffer frame;
  const std::size_t xStride = sizeof(glm::vec3);
  const std::size_t yStride = xStride * std::size_t(image.width);
  char* base = const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data()));
  frame.insert("R", Imf::Slice(Imf::FLOAT, base + 0 * sizeof(float), xStride, yStride));
  frame.insert("G", Imf::Slice(Imf::FLOAT, base + 1 * sizeof(float), xStride, yStride));
  frame.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xStride, yStride));
  try {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(image.height);
  } catch (const std::exception& e) {
    // OpenEXR reports a full disk as an exception whose text carries the system's reason.
    throw ResourceError(target.string() + ": write failed: " + oneLine(e.what()));
  }
}

Image readExr(const fs::path& file) {
  try {
    Imf::InputFile in(file.c_str());
    const Imath::Box2i window = in.header().dataWindow();
    const long long width = (long long)window.max.x - window.min.x + 1;
    const long long height = (long long)window.max.y - window.min.y + 1;
    requireSaneDimensions(file, width, height);
    const Imf::ChannelList& channels = in.header().channels();
    const bool hasRgb = channels.findChannel("R") || channels.findChannel("G") ||
                        channels.findChannel("B");
    const bool hasLuminance = channels.findChannel("Y") != nullptr;
    if (!hasRgb && !hasLuminance)
      throw InputError(file.string() + ": EXR has no R, G, B or Y channel");
    Image image(static_cast<int>(width), static_cast<int>(height));
    char* base = reinterpret_cast<char*>(image.pixels.data());
    auto channelSlice = [&](int c) {
      // Channels absent from the file read as the slice's fill value, 0.
      return Imf::Slice::Make(Imf::FLOAT, base + c * sizeof(float), window, sizeof(glm::vec3),
                              sizeof(glm::vec3) * std::size_t(width));
    };
    Imf::FrameBuffer frame;
    if (hasRgb) {
      frame.insert("R", channelSlice(0));
      frame.insert("G", channelSlice(1));
      frame.insert("B", channelSlice(2));
    } else {
      frame.insert("Y", channelSlice(0));  // grey image: copied to G and B below
    }
    in.setFrameBuffer(frame);
    in.readPixels(window.min.y, window.max.y);
    if (!hasRgb)
      for (glm::vec3& p : image.pixels) p = glm::vec3(p.x);
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file.string() + ": not a readable EXR file: " + oneLine(e.what()));
  }
}

// ---- PNG: display-referred 8-bit sRGB.

void writePngBytes(const std::vector<unsigned char>& bytes, int width, int height, const fs::path& path,
                   const fs::path& target) {
  // Encode to memory and write it ourselves: stbi_write_png ignores fwrite errors, so a
  // full disk would go unnoticed and a truncated PNG would be renamed over the target.
  std::string encoded;
  auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
  };
  if (!stbi_write_png_to_func(append, &encoded, width, height, 3, bytes.data(), width * 3))
    throw InputError(target.string() + ": cannot encode PNG");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(target.string() + ": cannot open for writing");
  out.write(encoded.data(), std::streamsize(encoded.size()));
  out.close();
  if (!out) throwWriteFailed(target, errno);
}

void writePng(const Image& image, const fs::path& path, const fs::path& target, float exposure) {
  writePngBytes(toDisplayRgb8(image, exposure), image.width, image.height, path, target);
}

Image readPng(const fs::path& file) {
  int width = 0, height = 0, channelsInFile = 0;
  // Check the header first so a garbage size never reaches the decoder's allocation.
  if (!stbi_info(file.c_str(), &width, &height, &channelsInFile))
    throw InputError(file.string() + ": not a readable PNG file: " + stbi_failure_reason());
  requireSaneDimensions(file, width, height);
  stbi_uc* bytes = stbi_load(file.c_str(), &width, &height, &channelsInFile, 3);
  if (!bytes) throw InputError(file.string() + ": not a readable PNG file: " + stbi_failure_reason());
  Image image(width, height);
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) image.pixels[i][c] = srgbToLinear(bytes[i * 3 + c] / 255.0f);
  stbi_image_free(bytes);
  return image;
}

}  // namespace

std::vector<unsigned char> toDisplayRgb8(const Image& image, float exposure) {
  std::vector<unsigned char> bytes(image.pixels.size() * 3);
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      float v = image.pixels[i][c] * exposure;
      v = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
      bytes[i * 3 + c] = static_cast<unsigned char>(std::lround(linearToSrgb(v) * 255.0f));
    }
  return bytes;
}

void writeDisplayPng(const std::vector<unsigned char>& rgb, int width, int height, const fs::path& file) {
  if (formatOf(file) != ImageFormat::Png)
    throw InputError(file.string() + ": a displayed frame is written as .png only");
  if (width <= 0 || height <= 0 || rgb.size() != std::size_t(width) * std::size_t(height) * 3)
    throw std::invalid_argument("writeDisplayPng(" + file.string() + "): " + std::to_string(rgb.size()) +
                                " bytes for " + std::to_string(width) + "x" + std::to_string(height));
  writeAtomically(file, [&](const fs::path& temp) { writePngBytes(rgb, width, height, temp, file); });
}

bool isSupportedImageExtension(const fs::path& file) {
  return formatOf(file) != ImageFormat::Unknown;
}

AtomicOutput imageOutput(const Image& image, const fs::path& file, float exposure) {
  const ImageFormat format = formatOf(file);
  if (format == ImageFormat::Unknown) failUnknownExtension(file);
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != std::size_t(image.width) * std::size_t(image.height))
    throw std::invalid_argument("writeImage(" + file.string() + "): image is " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " with " + std::to_string(image.pixels.size()) + " pixels");
  return {file, [&image, file, exposure, format](const fs::path& temp) {
            switch (format) {
              case ImageFormat::Png: writePng(image, temp, file, exposure); break;
              case ImageFormat::Pfm: writePfm(image, temp, file); break;
              case ImageFormat::Exr: writeExr(image, temp, file); break;
              case ImageFormat::Unknown: break;
            }
          }};
}

void writeImage(const Image& image, const fs::path& file, float exposure) {
  const AtomicOutput output = imageOutput(image, file, exposure);
  writeAtomically(output.target, output.write);
}

Image readImage(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file.string() + ": image file not found");
  requireRegularFile(file, "image");  // a FIFO or /dev/zero would never end
  switch (formatOf(file)) {
    case ImageFormat::Png: return readPng(file);
    case ImageFormat::Pfm: return readPfm(file);
    case ImageFormat::Exr: return readExr(file);
    case ImageFormat::Unknown: break;
  }
  failUnknownExtension(file);
}

}  // namespace sslpv

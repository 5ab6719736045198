#include "pvrr/base/image.h"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr {
namespace {

// Reading refuses images whose 8-bit RGB buffer would exceed this (a corrupt or hostile header).
constexpr std::size_t kMaxPngBytes = std::size_t(1) << 31;

void checkShape(int width, int height, std::size_t samples, const char* what) {
  PVRR_CHECK(width >= 0 && height >= 0, << what << " " << width << "x" << height);
  PVRR_CHECK(samples == 3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
             << what << " " << width << "x" << height << " holds " << samples << " samples");
}

std::string sizeLabel(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

template <class Image>
ImageDiff compareGeneric(const Image& a, const Image& b, double tolerance) {
  checkShape(a.width, a.height, a.rgb.size(), "compareImages: first image");
  checkShape(b.width, b.height, b.rgb.size(), "compareImages: second image");
  if (a.width != b.width || a.height != b.height) {
    throw Error("compareImages: image sizes differ (" + sizeLabel(a.width, a.height) + " vs " +
                sizeLabel(b.width, b.height) + ")");
  }
  ImageDiff d;
  d.width = a.width;
  d.height = a.height;
  const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  double sum = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    double pixel_max = 0;
    for (int c = 0; c < 3; ++c) {
      const double diff = std::abs(static_cast<double>(a.rgb[3 * p + c]) - static_cast<double>(b.rgb[3 * p + c]));
      sum += diff;
      pixel_max = std::max(pixel_max, diff);
    }
    d.max_abs = std::max(d.max_abs, pixel_max);
    if (pixel_max > tolerance) ++d.failing_pixels;
  }
  if (pixels > 0) {
    d.mean_abs = sum / (3.0 * static_cast<double>(pixels));
    d.failing_fraction = static_cast<double>(d.failing_pixels) / static_cast<double>(pixels);
  }
  return d;
}

}  // namespace

ImageRGB8::ImageRGB8(int width_px, int height_px)
    : width(width_px), height(height_px),
      rgb(3 * static_cast<std::size_t>(std::max(width_px, 0)) * static_cast<std::size_t>(std::max(height_px, 0))) {
  PVRR_CHECK(width_px >= 0 && height_px >= 0, << width_px << "x" << height_px);
}

ImageRGBf::ImageRGBf(int width_px, int height_px)
    : width(width_px), height(height_px),
      rgb(3 * static_cast<std::size_t>(std::max(width_px, 0)) * static_cast<std::size_t>(std::max(height_px, 0))) {
  PVRR_CHECK(width_px >= 0 && height_px >= 0, << width_px << "x" << height_px);
}

double srgbToLinear(double encoded) {
  const double v = std::clamp(encoded, 0.0, 1.0);
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

double linearToSrgb(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

float srgb8ToLinear(std::uint8_t code) {
  // 256 entries, computed once in double.
  static const auto table = [] {
    std::vector<float> t(256);
    for (int i = 0; i < 256; ++i) t[i] = static_cast<float>(srgbToLinear(i / 255.0));
    return t;
  }();
  return table[code];
}

std::uint8_t linearToSrgb8(double linear) {
  if (std::isnan(linear)) linear = 0;
  return static_cast<std::uint8_t>(std::lround(255.0 * linearToSrgb(linear)));
}

ImageRGBf toLinear(const ImageRGB8& image) {
  checkShape(image.width, image.height, image.rgb.size(), "toLinear");
  ImageRGBf out(image.width, image.height);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) out.rgb[i] = srgb8ToLinear(image.rgb[i]);
  return out;
}

ImageRGB8 toSrgb8(const ImageRGBf& image) {
  checkShape(image.width, image.height, image.rgb.size(), "toSrgb8");
  ImageRGB8 out(image.width, image.height);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) out.rgb[i] = linearToSrgb8(image.rgb[i]);
  return out;
}

ImageRGB8 rgbFromRgba(int width, int height, const std::vector<std::uint8_t>& rgba) {
  PVRR_CHECK(width >= 0 && height >= 0 &&
                 rgba.size() == 4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
             << width << "x" << height << " with " << rgba.size() << " RGBA bytes");
  ImageRGB8 out(width, height);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (std::size_t p = 0; p < pixels; ++p) {
    for (int c = 0; c < 3; ++c) out.rgb[3 * p + c] = rgba[4 * p + c];
  }
  return out;
}

ImageRGB8 readPng(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot read PNG: " + reason);
  }
  png.format = PNG_FORMAT_RGB;
  const std::size_t bytes = PNG_IMAGE_SIZE(png);
  if (png.width == 0 || png.height == 0 || png.width > 1u << 30 || png.height > 1u << 30 || bytes > kMaxPngBytes) {
    png_image_free(&png);
    throw Error(path + ": PNG of " + std::to_string(png.width) + "x" + std::to_string(png.height) +
                " pixels is empty or too large");
  }
  ImageRGB8 image(static_cast<int>(png.width), static_cast<int>(png.height));
  const png_color black{0, 0, 0};
  if (!png_image_finish_read(&png, &black, image.rgb.data(), 0, nullptr)) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot decode PNG: " + reason);
  }
  return image;
}

void writePngAtomic(const std::string& path, const ImageRGB8& image, MissingFolder folder) {
  checkShape(image.width, image.height, image.rgb.size(), "writePngAtomic");
  if (image.width == 0 || image.height == 0) {
    throw Error(path + ": cannot write an empty (" + sizeLabel(image.width, image.height) + ") PNG");
  }
  writeAtomic(
      path,
      [&](const std::string& temp) {
        std::FILE* file = std::fopen(temp.c_str(), "wb");
        if (file == nullptr) throw Error(path + ": cannot create the temporary file " + temp + ": " + std::strerror(errno));
        png_image png;
        std::memset(&png, 0, sizeof png);
        png.version = PNG_IMAGE_VERSION;
        png.width = static_cast<png_uint_32>(image.width);
        png.height = static_cast<png_uint_32>(image.height);
        png.format = PNG_FORMAT_RGB;
        const bool written = png_image_write_to_stdio(&png, file, 0, image.rgb.data(), 0, nullptr) != 0;
        const std::string png_reason = written ? "" : png.message;
        png_image_free(&png);
        const bool flushed = std::fflush(file) == 0 && !std::ferror(file);
        const int flush_errno = errno;
        const bool closed = std::fclose(file) == 0;
        if (!written || !flushed || !closed) {
          const std::string reason = !written ? "libpng: " + png_reason : std::string(std::strerror(flush_errno));
          throw Error(path + ": writing the PNG failed: " + reason);
        }
      },
      folder);
}

ImageDiff compareImages(const ImageRGB8& a, const ImageRGB8& b, double per_pixel_tolerance) {
  return compareGeneric(a, b, per_pixel_tolerance);
}

ImageDiff compareImages(const ImageRGBf& a, const ImageRGBf& b, double per_pixel_tolerance) {
  return compareGeneric(a, b, per_pixel_tolerance);
}

std::string describe(const ImageDiff& d) {
  const long long pixels = static_cast<long long>(d.width) * d.height;
  std::ostringstream os;
  os << d.width << "x" << d.height << ": max " << d.max_abs << ", mean " << d.mean_abs << ", " << d.failing_pixels
     << " of " << pixels << " pixels (" << 100.0 * d.failing_fraction << "%) over the tolerance";
  return os.str();
}

ImageRGB8 diffImage(const ImageRGB8& a, const ImageRGB8& b) {
  checkShape(a.width, a.height, a.rgb.size(), "diffImage: first image");
  checkShape(b.width, b.height, b.rgb.size(), "diffImage: second image");
  if (a.width != b.width || a.height != b.height) {
    throw Error("diffImage: image sizes differ (" + sizeLabel(a.width, a.height) + " vs " +
                sizeLabel(b.width, b.height) + ")");
  }
  // A difference of kSaturation code values or more is drawn full red.
  constexpr double kSaturation = 32;
  constexpr double kDimContext = 0.3;
  ImageRGB8 out(a.width, a.height);
  const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::uint8_t* pa = &a.rgb[3 * p];
    const std::uint8_t* pb = &b.rgb[3 * p];
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(pa[c]) - int(pb[c])));
    // Rec. 709 luma weights on the code values: a context picture, not a colorimetric quantity.
    const double luma = 0.2126 * pa[0] + 0.7152 * pa[1] + 0.0722 * pa[2];
    const auto dim = static_cast<std::uint8_t>(std::lround(kDimContext * luma));
    std::uint8_t* po = &out.rgb[3 * p];
    if (d == 0) {
      po[0] = po[1] = po[2] = dim;
    } else {
      po[0] = static_cast<std::uint8_t>(std::lround(96 + 159 * std::min(1.0, d / kSaturation)));
      po[1] = po[2] = 0;
    }
  }
  return out;
}

void writeDiffImage(const ImageRGB8& a, const ImageRGB8& b, const std::string& path) {
  writePngAtomic(path, diffImage(a, b));
}

}  // namespace pvrr

// Images on the CPU: 8-bit sRGB and linear float RGB, PNG input/output (libpng) with atomic writes, the sRGB
// transfer curve, and the image comparator used by the tests and by the CLI. No GL here.
//
// Conventions: pixels are stored row-major, rows TOP-DOWN (row 0 is the top of the picture, as in PNG files),
// 3 interleaved channels R, G, B; pixel (x, y) starts at index 3 * (y * width + x).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pvrr/base/atomic_file.h"

namespace pvrr {

// 8 bits per channel, sRGB-encoded (what PNG files and RGBA8 framebuffers hold).
struct ImageRGB8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;

  ImageRGB8() = default;
  ImageRGB8(int width_px, int height_px);  // black
  std::uint8_t* at(int x, int y) { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
  const std::uint8_t* at(int x, int y) const { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
};

// Linear-light RGB in float (1 = the sRGB white), e.g. radiance before display encoding.
struct ImageRGBf {
  int width = 0, height = 0;
  std::vector<float> rgb;

  ImageRGBf() = default;
  ImageRGBf(int width_px, int height_px);  // black
  float* at(int x, int y) { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
  const float* at(int x, int y) const { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
};

// The exact sRGB transfer curve of IEC 61966-2-1: encoded = 12.92 L for L <= 0.0031308, else
// 1.055 L^(1/2.4) - 0.055 (and its inverse, with the threshold 0.04045 on the encoded side). Values in [0, 1];
// inputs outside are clamped.
double srgbToLinear(double encoded);
double linearToSrgb(double linear);
// Code value 0..255 <-> linear; linearToSrgb8 rounds to nearest after clamping to [0, 1].
float srgb8ToLinear(std::uint8_t code);
std::uint8_t linearToSrgb8(double linear);

ImageRGBf toLinear(const ImageRGB8& image);
ImageRGB8 toSrgb8(const ImageRGBf& image);

// An RGB8 image from RGBA8 pixels in the same (top-down) layout, e.g. Framebuffer::readRGBA8; alpha is dropped.
ImageRGB8 rgbFromRgba(int width, int height, const std::vector<std::uint8_t>& rgba);

// Reads any PNG (grey, palette, 16-bit, with alpha) as 8-bit sRGB; alpha is composited onto black. Throws
// pvrr::Error naming the path and libpng's reason on failure.
ImageRGB8 readPng(const std::string& path);

// Writes `image` to `path` atomically (pvrr/base/atomic_file.h: a temporary beside it, renamed onto it when
// complete, or kept for the command's OutputTransaction). On any failure pvrr::Error names the path and the reason
// and `path` is left as it was. A missing folder is an error unless `folder` says to create it.
void writePngAtomic(const std::string& path, const ImageRGB8& image, MissingFolder folder = MissingFolder::Fail);

// How two images of the same size differ. For RGB8 differences are in code values (0..255), for float images in
// the images' own units. max_abs: the largest difference of any channel of any pixel. mean_abs: the mean over all
// channel samples. A pixel FAILS when its largest channel difference exceeds the tolerance; failing_fraction is
// failing pixels / all pixels. Metrics do not grow with image size (see the house style).
struct ImageDiff {
  double max_abs = 0;
  double mean_abs = 0;
  double failing_fraction = 0;
  long long failing_pixels = 0;
  int width = 0, height = 0;
};

// Throws pvrr::Error when the sizes differ.
ImageDiff compareImages(const ImageRGB8& a, const ImageRGB8& b, double per_pixel_tolerance);
ImageDiff compareImages(const ImageRGBf& a, const ImageRGBf& b, double per_pixel_tolerance);
// "64x48: max 3, mean 0.0125, 2 of 3072 pixels (0.065%) over the tolerance"
std::string describe(const ImageDiff& diff);

// A visual diff of two same-size images: identical pixels show `a` as dim grey (30% of its luma), differing pixels
// are red, from dark red (a difference of 1 code value) to full red (32 or more). Written with writePngAtomic.
ImageRGB8 diffImage(const ImageRGB8& a, const ImageRGB8& b);
void writeDiffImage(const ImageRGB8& a, const ImageRGB8& b, const std::string& path);

}  // namespace pvrr

// Procedural textures for environment objects (the "procedural" textures of docs/scene-format.md),
// generated on the CPU, deterministically (the same description gives the same bytes on every platform).
#pragma once
#include <cstdint>
#include <vector>

#include "pvrr/scene/scene_desc.h"

namespace pvrr {

// RGB8, sRGB-encoded (like a PNG file; pvrr/base/image.h linearToSrgb8), row-major, row 0 at the top (texture
// v = 1 there).
struct TextureImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3
  const uint8_t* at(int x, int y) const { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
};

// Generates a procedural texture. Throws pvrr::Error for an image texture (those are read from their file)
// or for a description the loader would have rejected (sizes out of [8, 1024], too many rows for the
// resolution).
TextureImage generateTexture(const TextureDesc& desc);

// Limits the loader checks so that every accepted description can be generated legibly:
// the most eye-chart rows a width x height image holds (strokes of at least one pixel, strictly decreasing
// from row to row; 0 when not even one fits), and the most text lines a page of `height` pixels holds (a
// line pitch of at least 10 px).
int eyeChartMaxRows(int width, int height);
int pageMaxLines(int height);

// Ratio of successive optotype sizes on the eye chart: 0.1 logMAR per row, 10^-0.1.
constexpr double kEyeChartRowRatio = 0.7943282347242815;
// Eye-chart rows hold at most this many optotypes (row r holds min(r + 1, fit)).
constexpr int kEyeChartMaxLetters = 8;

}  // namespace pvrr

// One rendered frame's per-pixel outputs, from the reference tracer (pvrr/trace/tracer.h) or a raster mode
// (pvrr/gl/renderer.h: gl::RasterFrame adds the per-element state of the pvrr mode). What the accuracy
// figures (pvrr/analysis/accuracy.h), the CLI's pictures and the tests read.
//
// Conventions: every per-pixel buffer is row-major with rows TOP-DOWN (row 0 is the top of the picture), index
// y * width + x, and holds width * height values where it is filled (an empty buffer: not produced by this
// frame). Points are world coordinates in the scene's units (metres or millimetres, as the scene says).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/base/image.h"
#include "pvrr/base/stats.h"

namespace pvrr {

struct Frame {
  int width = 0, height = 0;
  // Linear RGB (1 = the sRGB white), before display encoding.
  std::vector<Vec3> color;
  // The point each pixel sees: the tracer's final diffuse hit (o + far * d for an escaping path); a raster
  // mode's seen point (double, reconstructed from camera-relative floats). Empty for a raster frame drawn
  // colour only (gl::RendererOptions::seen_points off).
  std::vector<Vec3> seen;
  // The first optical element (mirror or lens) the pixel's ray meets, its index in Scene::elements; -1 for
  // none. Empty where `seen` is.
  std::vector<int> element;
  // Where the pixel's ray meets that element (undefined where element is -1). Empty where `seen` is.
  std::vector<Vec3> element_point;
  // The reference only: specular events (reflections, refractions, TIRs) of each pixel's path; empty otherwise.
  std::vector<int> bounces;
  // The reference only: 1 where the pixel's path ended at the depth limit (render.max_depth) on an element, 0
  // elsewhere; empty otherwise. Such a path has no seen point: `seen` is the element point where it stopped and
  // the colour black, so the accuracy figures compare those pixels by colour only (pvrr/analysis/accuracy.h).
  std::vector<uint8_t> depth_limited;
  // The reference with rgb dispersion only (empty otherwise): the seen point of each channel's own ray per
  // pixel (R = C line, G = d line, B = F line; pvrr/optics/spectrum.h). Equal to `seen` for all three where the path
  // crosses no lens.
  std::array<std::vector<Vec3>, 3> channel_seen;
  // The frame's time (ms): the tracer's multithreaded render; a raster frame's CPU + GPU (finished) time.
  double frame_ms = 0;
  // What each stage did and took (pvrr/base/stats.h); the tracer reports one stage, "ray-trace".
  FrameStages stages;
};

// The 8-bit sRGB picture of linear RGB colours (row-major, rows top-down): each channel clamped to [0, 1] and
// encoded with linearToSrgb8 (pvrr/base/image.h); a non-finite colour is written black and counted in
// `non_finite` (optional). What `pvrr render` and `pvrr compare` write and the golden-image tests compare.
ImageRGB8 srgbPicture(int width, int height, const std::vector<Vec3>& linear, size_t* non_finite = nullptr);
inline ImageRGB8 srgbPicture(const Frame& f, size_t* non_finite = nullptr) {
  return srgbPicture(f.width, f.height, f.color, non_finite);
}

}  // namespace pvrr

// The viewer's present pass: the renderer's linear frame (Renderer::colorTexture) copied into the window's
// default framebuffer, sRGB-encoded exactly as pvrr render encodes a picture (pvrr::linearToSrgb8 of the 16-bit
// value the renderer's target holds), outside an optional hole: the panel's opaque rectangle, where the frame
// would be drawn over (docs/performance.md "The window's frame: where its time goes"). Used where the renderer
// does not draw its second pass into the window itself (gl::RendererOptions::into_default_framebuffer: beside a
// live reference, for the screenshot of the frame alone, a window without an sRGB or depth buffer, or
// PVRR_VIEW_PRESENT_PASS=1).
//
// The encode (shaders/srgb_encode.glsl) reads a table of 4096 buckets from a uniform block; passes that present
// the frame as this one does (the wipe, app/view/wipe.h) include the same file and bind the same block.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "pvrr/gl/program.h"

namespace pvrr::app::view {

// A rectangle of window pixels, rows top-down: [x0, x1) x [y0, y1).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool operator==(const PixelRect& o) const { return x0 == o.x0 && y0 == o.y0 && x1 == o.x1 && y1 == o.y1; }
  bool contains(const PixelRect& o) const { return o.x0 >= x0 && o.y0 >= y0 && o.x1 <= x1 && o.y1 <= y1; }
};

// The uniform block SrgbBuckets of shaders/srgb_encode.glsl: 2048 words, each two buckets (16 bits, the lower
// first); bucket j covers k = 16 j .. 16 j + 15 (k / 65535 linear): bits 0-7 the code of k = 16 j, bits 8-12 the
// offset in the bucket from which the code is one more (16: none). Checks (PVRR_CHECK) that no bucket steps twice.
std::vector<std::uint32_t> srgbBucketWords();
// The shader's encode of the 16-bit value k (0..65535) from those words, in C++: for tests.
int srgbCodeFromBuckets(const std::vector<std::uint32_t>& words, int k);

// The GL objects need the window's context current: made, used and destroyed with it.
class PresentPass {
 public:
  // `empty_vao`: a vertex array object of this context without attributes (the full-screen triangle).
  explicit PresentPass(unsigned empty_vao);
  ~PresentPass();
  PresentPass(const PresentPass&) = delete;
  PresentPass& operator=(const PresentPass&) = delete;

  // Binds a program's SrgbBuckets block to the table's binding point (once, after linking).
  static void bindBlockOf(unsigned program);
  // Binds the table to that binding point (before each draw of a program that encodes).
  void bindTable() const;
  // Draws `texture` (linear, width x height) into the default framebuffer, but for the pixels of `hole`.
  void present(unsigned texture, int width, int height, const std::optional<PixelRect>& hole = std::nullopt) const;

 private:
  gl::Program program_;
  unsigned vao_ = 0, table_ = 0;
};

}  // namespace pvrr::app::view

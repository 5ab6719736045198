// The viewer's A/B wipe and error overlay: presents the mode's frame left of a vertical split line and the live
// reference (app/view/reference_tiles.h) right of it, and over the mode's side, when asked, the per-pixel error
// heat map. Used only while a reference exists; the window's plain present (window.h) draws every other frame.
//
// The reference and the heat map are uploaded as 8-bit sRGB codes (computed on the CPU as pvrr compare writes
// its pictures) and shown unchanged; the mode's frame is encoded as the present pass encodes it. Reference
// pixels not traced yet show the mode's frame at half brightness; with the overlay, pixels without an error
// (no element, or a non-finite one) show it at kOverlayDim.
#pragma once
#include <cstdint>
#include <vector>

#include "app/view/reference_tiles.h"
#include "pvrr/gl/program.h"

namespace pvrr::app::view {

class Window;

class Wipe {
 public:
  explicit Wipe(Window& window);
  ~Wipe();
  Wipe(const Wipe&) = delete;
  Wipe& operator=(const Wipe&) = delete;

  // Sizes (when the size changed) and clears the reference and heat-map textures for a new reference of width x
  // height.
  void reset(int width, int height);
  // Uploads the given tiles of `rgba` (width x height RGBA8, rows top-down) to the reference texture.
  void uploadTiles(const std::vector<TileRect>& tiles, const std::vector<std::uint8_t>& rgba);
  // Uploads the heat map (width x height RGBA8, rows top-down).
  void uploadHeat(const std::vector<std::uint8_t>& rgba);
  // Draws into the window's default framebuffer: `frame` (Renderer::colorTexture) left of column split_px,
  // the reference from it on; the heat map over the left side when `overlay`; a one-pixel line left of the
  // split when 0 < split_px < width.
  void present(unsigned frame, int width, int height, double split_px, bool overlay);

 private:
  Window& window_;
  gl::Program program_;
  unsigned reference_ = 0, heat_ = 0, framebuffer_ = 0;  // framebuffer_: for clearing them
  int width_ = 0, height_ = 0;
};

}  // namespace pvrr::app::view

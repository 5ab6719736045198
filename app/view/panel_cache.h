// The panel drawn from a picture of it: Dear ImGui's panel window is drawn into a texture at most every
// kPanelRefreshMs and copied into the window each frame in between (glBlitFramebuffer), instead of drawn anew:
// llvmpipe drew its text and background in 6-7 CPU ms a frame at 1280 x 720 (docs/performance.md "The window's
// frame: where its time goes"). The viewer draws the panel live (every frame) while it is worked (the mouse
// over it, an item active, a popup open) and for screenshots with the panel; the rest of ImGui's frame (the
// field-of-view overlay under the panel) is drawn live every frame. The panel's numbers are then at most
// kPanelRefreshMs old.
//
// Where the window can show part of its back buffer (Window::showsPart, GLX_MESA_copy_sub_buffer), a frame
// whose panel picture the window already shows (the last frame shown whole copied it there, nothing was drawn
// over it, the window lost none of its content since) keeps it: the panel is not drawn at all and the frame is
// shown less the panel's rectangle (docs/performance.md "The window's frame: where its time goes").
#pragma once
#include <chrono>

#include "app/view/present_pass.h"

struct ImDrawData;
struct ImDrawList;

namespace pvrr::app::view {

inline constexpr double kPanelRefreshMs = 250;

// GL objects of the window's context: made, used and destroyed with it current.
class PanelCache {
 public:
  PanelCache() = default;
  ~PanelCache();
  PanelCache(const PanelCache&) = delete;
  PanelCache& operator=(const PanelCache&) = delete;

  // Draws `dd` into the default framebuffer (width x height): its lists in order, the panel's (`panel`, whose
  // pixels lie in `rect`) copied from the picture, which is drawn anew first when it is older than
  // kPanelRefreshMs, its rectangle or the window's size changed, or invalidate() was called.
  // With `may_keep`, when the window shows this picture at `rect` already (keepable), the panel is not drawn
  // (the lists under it are): returns whether it was kept, the frame then to be shown less `rect`.
  bool draw(ImDrawData& dd, const ImDrawList* panel, const PixelRect& rect, int width, int height,
            bool may_keep = false);
  // The next draw makes the picture anew (the panel was drawn live meanwhile).
  void invalidate() {
    valid_ = false;
    from_picture_ = false;
  }
  // The frame was shown: whole (what the window shows under the panel is this frame's), or less the kept panel.
  void shown(bool whole);
  // The window may have lost what it showed (an expose, a resize): the next frame is shown whole.
  void lost() { shown_valid_ = false; }
  int pictures() const { return pictures_; }  // pictures made
  int copies() const { return copies_; }      // frames drawn from a picture
  int kept() const { return kept_; }          // frames that kept the panel the window showed (not drawn)

 private:
  unsigned framebuffer_ = 0, texture_ = 0;
  int width_ = 0, height_ = 0;
  bool valid_ = false;
  PixelRect rect_;
  std::chrono::steady_clock::time_point made_{};
  int pictures_ = 0, copies_ = 0, kept_ = 0;
  // This frame: the panel copied from its picture with no list drawn over it.
  bool from_picture_ = false;
  // What the window shows in the panel's place: picture number shown_picture_ at shown_rect_ (shown_valid_).
  bool shown_valid_ = false;
  int shown_picture_ = 0;
  PixelRect shown_rect_;
};

// ImGui's draw data of a subset of `dd`'s lists (those from `first` to before `last`), for drawing in parts.
void drawListsOf(ImDrawData& dd, int first, int last);

}  // namespace pvrr::app::view

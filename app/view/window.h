// The viewer's window: GLFW 3 with a GL 4.5 core context (3.3 at least) adopted as a pvrr::gl::GlContext, so the
// same Renderer draws in it; Dear ImGui for the panel. The renderer's second pass draws into the window's back
// buffer itself, sRGB-encoded by GL (takesFrameDirectly), or its frame is presented sRGB-encoded from its texture
// (present()). The only place that includes GLFW; GL through glad (pvrr/gl/gl.h).
#pragma once
#include <functional>
#include <memory>
#include <string>

#include <optional>

#include "app/view/panel_cache.h"
#include "app/view/present_pass.h"
#include "pvrr/base/image.h"
#include "pvrr/gl/context.h"

struct GLFWwindow;

namespace pvrr::app::view {

// Which GLFW context API: Auto (GLX, then EGL), Glx, Egl.
enum class WindowGl { Auto, Glx, Egl };
// "auto" | "glx" | "egl"; throws pvrr::Error listing the choices otherwise.
WindowGl parseWindowGl(const std::string& name);

// Compiles and links a GL program of a vertex and a fragment shader in the current context; throws pvrr::Error
// "pvrr view: the WHAT program does not compile: LOG" (or link).
unsigned buildProgram(const char* vertex_source, const char* fragment_source, const std::string& what);

// The present pass's full-screen triangle (gl_VertexID 0..2, no attributes): a vertex shader for any pass
// that draws every pixel of the window once.
extern const char* const kFullScreenVs;

// The GL state of a present pass: the window's framebuffer, the full viewport, no depth test, blending,
// culling, scissor or sRGB conversion (the present shaders encode sRGB themselves). Used by PresentPass::present
// and Wipe::present.
void beginPresentPass(int width, int height);

class Window;

// A second GL context of the window's kind (a hidden 1 x 1 window of the same API), for GL work on another thread
// (the live reference's seen points, app/view/seen_frames.h): made and destroyed on the window's thread (GLFW's
// rule), adopted (gl::GlContext::adopt(foreign())) and used on one other thread, and current on no thread when
// destroyed. Its entry points are the window's (ForeignContext::entry_points_of): glad's are not reloaded for it.
class WorkerContext {
 public:
  explicit WorkerContext(Window& window);
  ~WorkerContext();
  WorkerContext(const WorkerContext&) = delete;
  WorkerContext& operator=(const WorkerContext&) = delete;
  gl::ForeignContext foreign() const;

 private:
  Window& window_;
  GLFWwindow* hidden_ = nullptr;
};

class Window {
 public:
  // Opens a width x height window (framebuffer pixels). `vsync`: swap interval 1, else 0 (scripted runs, which
  // measure). Throws pvrr::Error saying why (no display: "run under xvfb-run"; no GL context of the kind).
  Window(int width, int height, WindowGl api, bool vsync, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  gl::GlContext& context() { return *context_; }
  GLFWwindow* handle() { return window_; }
  bool closeRequested() const;
  // The framebuffer's size as the last poll of events left it (swapAndPoll; a resize shows from the next frame).
  void framebufferSize(int* width, int* height) const;
  // Draws `texture` (a linear colour texture of the framebuffer's size, Renderer::colorTexture) into the default
  // framebuffer, encoded to sRGB as pvrr::srgbPicture encodes a picture, but for the pixels of `hole` (where an
  // opaque panel will be drawn over it).
  void present(unsigned texture, int width, int height, const std::optional<PixelRect>& hole = std::nullopt);
  // Whether the renderer may draw its second pass into the window's back buffer
  // (gl::RendererOptions::into_default_framebuffer): it has a depth buffer and an sRGB encoding. Otherwise
  // present() draws the renderer's texture into it.
  bool takesFrameDirectly() const { return srgb_ && depth_bits_ > 0; }
  // The back buffer's depth bits and whether its colour is sRGB-encoded (for the stats).
  int depthBits() const { return depth_bits_; }
  bool srgbCapable() const { return srgb_; }
  // ImGui frame: begin before building the panel, end after it (ImGui::Render: the draw lists made, nothing
  // drawn), then draw it over the presented frame.
  void beginPanel();
  void endPanel();
  // Draws ImGui's frame over the presented one: all of it anew (`panel` null), or with the panel's draw list
  // `panel` (its pixels in `rect`) copied from its picture (panel_cache.h). With `may_keep` (the back buffer's
  // panel need not be read: no screenshot with the panel) and where the window shows part of its back buffer
  // (showsPart), a panel the window shows already is kept: not drawn, and the next swapAndPoll shows the frame
  // less `rect`.
  void drawPanel(const ImDrawList* panel = nullptr, const PixelRect& rect = {}, bool may_keep = false);
  // Whether the window shows part of its back buffer (GLX_MESA_copy_sub_buffer) in place of a swap where the
  // panel is kept: GLX only, and where a swap would not wait for the display anyway (no vsync asked, or GLX
  // without swap control, as Mesa's software drisw under Xvfb). PVRR_VIEW_WHOLE_SWAP=1 turns it off, to
  // measure the two against each other in one build (docs/performance.md).
  bool showsPart() const { return copy_sub_buffer_ != nullptr; }
  // Frames shown less the kept panel's rectangle.
  int partShows() const { return part_shows_; }
  const PanelCache& panelCache() const { return *panel_cache_; }
  // The back buffer's pixels (after present and before swap), rows top-down.
  ImageRGB8 readBackBuffer(int width, int height) const;
  // The window's pixels as the display shows them (read from the X server), rows top-down: for the tests of
  // what a frame shown in part leaves on screen. X11 only; throws pvrr::Error otherwise.
  ImageRGB8 readShown(int width, int height) const;
  // Shows the back buffer: whole (a swap), or after a drawPanel that kept the panel, all of it but the panel's
  // rectangle (copied to the window; the back buffer is not swapped); then polls events.
  void swapAndPoll();
  // The present pass, whose sRGB table passes that present the frame as present() does bind
  // (shaders/srgb_encode.glsl).
  const PresentPass& presentPass() const { return *present_; }
  // An empty vertex array object of this context, for full-screen passes.
  unsigned emptyVertexArray() const { return vao_; }

 private:
  friend class WorkerContext;
  GLFWwindow* window_ = nullptr;
  int api_hint_ = 0;  // the GLFW context creation API that opened it
  std::unique_ptr<gl::GlContext> context_;
  unsigned vao_ = 0;
  std::unique_ptr<PresentPass> present_;
  std::unique_ptr<PanelCache> panel_cache_;
  bool imgui_ = false;
  int depth_bits_ = 0;
  bool srgb_ = false;
  // glXCopySubBufferMESA, where the window shows part of its back buffer (showsPart), and its display and
  // drawable.
  void (*copy_sub_buffer_)(void* display, unsigned long drawable, int x, int y, int width, int height) = nullptr;
  void* x_display_ = nullptr;
  unsigned long glx_window_ = 0;
  std::optional<PixelRect> kept_;  // the panel's rectangle this frame kept (drawPanel)
  int part_shows_ = 0;
};

}  // namespace pvrr::app::view

#include "app/view/window.h"

#include "pvrr/gl/gl.h"  // glad first: GLFW is told to include no GL header

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "app/view/x11_image.h"
#include "pvrr/base/error.h"

// GLFW's X11 and GLX natives, declared here rather than through GLFW/glfw3native.h (which includes Xlib's and
// GLX's headers, their macros and GL/gl.h after glad).
extern "C" {
void* glfwGetX11Display(void);
unsigned long glfwGetGLXWindow(GLFWwindow* window);
unsigned long glfwGetX11Window(GLFWwindow* window);
}

namespace pvrr::app::view {
namespace {

// The window showed nothing of its own or lost it since the last swap (an expose, a resize): set by GLFW's
// callbacks (one visible window a process), read after each poll.
bool g_window_lost = false;
// The window's framebuffer size as the last poll left it (GLFW's callback): glfwGetFramebufferSize asks the X
// server each call (XGetWindowAttributes, a round trip), and the frame asked it three times.
int g_framebuffer_width = 0, g_framebuffer_height = 0;

std::string g_glfw_error;  // the last GLFW error, for the messages
void onGlfwError(int code, const char* text) { g_glfw_error = std::string(text) + " (GLFW error " + std::to_string(code) + ")"; }

GLuint compile(GLenum kind, const char* source, const std::string& what) {
  const GLuint s = glCreateShader(kind);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw Error("pvrr view: the " + what + " program does not compile: " + log);
  }
  return s;
}

GLFWwindow* openWindow(int width, int height, int api, const std::string& title, bool visible = true) {
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, api);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  // The renderer's second pass draws into the window (Window::takesFrameDirectly): a depth buffer, and a colour
  // buffer that GL can encode to sRGB.
  // No stencil: llvmpipe clears a depth buffer with stencil bits word by word, keeping them (0.52 against 0.19 ms
  // at 1280 x 720, docs/performance.md).
  glfwWindowHint(GLFW_DEPTH_BITS, 24);
  glfwWindowHint(GLFW_STENCIL_BITS, 0);
  glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_TRUE);
  for (const auto& [major, minor] : {std::pair{4, 5}, std::pair{gl::kGlFloorMajor, gl::kGlFloorMinor}}) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, major);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor);
    if (GLFWwindow* w = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr)) return w;
  }
  return nullptr;
}

}  // namespace

const char* const kFullScreenVs = R"(#version 330 core
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
})";

unsigned buildProgram(const char* vertex_source, const char* fragment_source, const std::string& what) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source, what),
               fs = compile(GL_FRAGMENT_SHADER, fragment_source, what);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    glDeleteProgram(program);
    throw Error("pvrr view: the " + what + " program does not link");
  }
  return program;
}

WindowGl parseWindowGl(const std::string& name) {
  if (name == "auto") return WindowGl::Auto;
  if (name == "glx") return WindowGl::Glx;
  if (name == "egl") return WindowGl::Egl;
  throw Error("pvrr view: --gl: expected one of auto, glx, egl; got \"" + name + "\"");
}

Window::Window(int width, int height, WindowGl api, bool vsync, const std::string& title) {
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) {
    const char* display = std::getenv("DISPLAY");
    throw Error("pvrr view: cannot open a window: " + g_glfw_error +
                (display && *display ? "" : "; DISPLAY is not set (run under xvfb-run -a for a virtual display)"));
  }
  std::string tried;
  std::string name;
  for (const auto& [kind, api_hint, label] : {std::tuple{WindowGl::Glx, GLFW_NATIVE_CONTEXT_API, "glx"},
                                              std::tuple{WindowGl::Egl, GLFW_EGL_CONTEXT_API, "egl"}}) {
    if (api != WindowGl::Auto && api != kind) continue;
    g_glfw_error.clear();
    window_ = openWindow(width, height, api_hint, title);
    if (window_) {
      name = std::string("glfw-") + label;
      api_hint_ = api_hint;
      break;
    }
    tried += std::string("\n  ") + label + ": " + g_glfw_error;
  }
  if (!window_) {
    glfwTerminate();
    throw Error("pvrr view: could not open a window with a GL 3.3+ core context; tried:" + tried);
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(vsync ? 1 : 0);
  if (api_hint_ == GLFW_NATIVE_CONTEXT_API && glfwExtensionSupported("GLX_MESA_copy_sub_buffer")) {
    // A copy of part of the back buffer is not synchronised to the display: only where a swap would not wait
    // for it either.
    const bool swap_control = glfwExtensionSupported("GLX_EXT_swap_control") ||
                              glfwExtensionSupported("GLX_MESA_swap_control") ||
                              glfwExtensionSupported("GLX_SGI_swap_control");
    const char* whole = std::getenv("PVRR_VIEW_WHOLE_SWAP");
    if ((!vsync || !swap_control) && !(whole && std::string(whole) == "1")) {
      copy_sub_buffer_ = reinterpret_cast<decltype(copy_sub_buffer_)>(glfwGetProcAddress("glXCopySubBufferMESA"));
      x_display_ = glfwGetX11Display();
      glx_window_ = glfwGetGLXWindow(window_);
      if (!x_display_ || !glx_window_) copy_sub_buffer_ = nullptr;
    }
  }
  glfwSetWindowRefreshCallback(window_, [](GLFWwindow*) { g_window_lost = true; });
  glfwGetFramebufferSize(window_, &g_framebuffer_width, &g_framebuffer_height);
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow*, int width, int height) {
    g_window_lost = true;
    g_framebuffer_width = width;
    g_framebuffer_height = height;
  });
  GLFWwindow* w = window_;
  gl::ForeignContext fc;
  fc.backend_name = name;
  fc.make_current = [w] { glfwMakeContextCurrent(w); };
  fc.release_current = [w] {
    if (glfwGetCurrentContext() == w) glfwMakeContextCurrent(nullptr);
  };
  fc.get_proc_address = glfwGetProcAddress;
  context_ = gl::GlContext::adopt(std::move(fc));

  {
    // What the window's back buffer is (GLX may give another configuration than asked for): the renderer draws
    // into it only with a depth buffer and an sRGB encoding that GL_FRAMEBUFFER_SRGB turns on.
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GLint encoding = 0, depth_bits = 0;
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_BACK_LEFT, GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING,
                                          &encoding);
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_DEPTH, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &depth_bits);
    while (glGetError() != GL_NO_ERROR) {
    }
    depth_bits_ = depth_bits;
    srgb_ = encoding == GL_SRGB;
  }
  glGenVertexArrays(1, &vao_);
  present_ = std::make_unique<PresentPass>(vao_);
  panel_cache_ = std::make_unique<PanelCache>();

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini: a run writes only the files it is asked for
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 0;  // the panel's rectangle is all opaque (the present pass skips it)
  ImGui_ImplGlfw_InitForOpenGL(window_, true);  // chains the callbacks installed before it
  ImGui_ImplOpenGL3_Init("#version 330 core");
  imgui_ = true;
}

Window::~Window() {
  if (imgui_) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  if (context_) {
    context_->makeCurrent();
    present_.reset();
    panel_cache_.reset();
    if (vao_) glDeleteVertexArrays(1, &vao_);
    context_.reset();
  }
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

WorkerContext::WorkerContext(Window& window) : window_(window) {
  hidden_ = openWindow(1, 1, window.api_hint_, "pvrr view: worker", /*visible=*/false);
  if (!hidden_) throw Error("pvrr view: could not open a second GL context for the worker thread: " + g_glfw_error);
}

WorkerContext::~WorkerContext() { glfwDestroyWindow(hidden_); }

gl::ForeignContext WorkerContext::foreign() const {
  GLFWwindow* w = hidden_;
  gl::ForeignContext fc;
  fc.backend_name = window_.context().backendName() + " (worker)";
  fc.make_current = [w] { glfwMakeContextCurrent(w); };
  fc.release_current = [w] {
    if (glfwGetCurrentContext() == w) glfwMakeContextCurrent(nullptr);
  };
  fc.get_proc_address = glfwGetProcAddress;
  fc.entry_points_of = &window_.context();
  return fc;
}

bool Window::closeRequested() const { return glfwWindowShouldClose(window_); }

void Window::framebufferSize(int* width, int* height) const {
  *width = g_framebuffer_width;
  *height = g_framebuffer_height;
}

void beginPresentPass(int width, int height) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_FRAMEBUFFER_SRGB);
}

void Window::present(unsigned texture, int width, int height, const std::optional<PixelRect>& hole) {
  present_->present(texture, width, height, hole);
}

void Window::beginPanel() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

void Window::endPanel() { ImGui::Render(); }

void Window::drawPanel(const ImDrawList* panel, const PixelRect& rect, bool may_keep) {
  kept_.reset();
  if (!panel) {
    panel_cache_->invalidate();  // the panel may have changed since its picture
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    return;
  }
  int width = 0, height = 0;
  framebufferSize(&width, &height);
  if (panel_cache_->draw(*ImGui::GetDrawData(), panel, rect, width, height, may_keep && showsPart())) kept_ = rect;
}

ImageRGB8 Window::readBackBuffer(int width, int height) const {
  std::vector<std::uint8_t> rgba(size_t(width) * size_t(height) * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  gl::checkGlError("reading the window's pixels");
  // GL's rows are bottom-up.
  std::vector<std::uint8_t> flipped(rgba.size());
  const size_t row = size_t(width) * 4;
  for (int y = 0; y < height; ++y)
    std::copy_n(rgba.begin() + std::ptrdiff_t(size_t(height - 1 - y) * row), row, flipped.begin() + std::ptrdiff_t(size_t(y) * row));
  return rgbFromRgba(width, height, flipped);
}

ImageRGB8 Window::readShown(int width, int height) const {
  void* display = glfwGetX11Display();
  const unsigned long window = glfwGetX11Window(window_);
  if (!display || !window) throw Error("pvrr view: a screenshot of the window as shown needs an X11 window");
  return readX11Window(display, window, width, height);
}

void Window::swapAndPoll() {
  int width = 0, height = 0;
  framebufferSize(&width, &height);
  if (kept_ && copy_sub_buffer_) {
    // The window less the kept panel's rectangle, in up to four bands (GL's rows, bottom-up): above it, below
    // it, left and right of it. The panel's pixels on screen stay those the last whole frame showed.
    const PixelRect p{std::clamp(kept_->x0, 0, width), std::clamp(kept_->y0, 0, height),
                      std::clamp(kept_->x1, 0, width), std::clamp(kept_->y1, 0, height)};
    for (const PixelRect& r : {PixelRect{0, 0, width, p.y0}, PixelRect{0, p.y1, width, height},
                               PixelRect{0, p.y0, p.x0, p.y1}, PixelRect{p.x1, p.y0, width, p.y1}})
      if (!r.empty()) copy_sub_buffer_(x_display_, glx_window_, r.x0, height - r.y1, r.x1 - r.x0, r.y1 - r.y0);
    ++part_shows_;
    panel_cache_->shown(false);
  } else {
    glfwSwapBuffers(window_);
    panel_cache_->shown(true);
  }
  kept_.reset();
  g_window_lost = false;
  glfwPollEvents();
  if (g_window_lost) panel_cache_->lost();
}

}  // namespace pvrr::app::view

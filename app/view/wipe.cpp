#include "app/view/wipe.h"

#include "pvrr/gl/gl.h"  // glad first

#include "app/view/present_pass.h"
#include "app/view/window.h"

namespace pvrr::app::view {
namespace {

// The mode's frame encoded as the present pass encodes it (shaders/srgb_encode.glsl); the reference and heat map
// are 8-bit codes already, stored top-down (flipped here: GL's rows are bottom-up).
constexpr const char* kWipeFs = R"(#version 330 core
#include "srgb_encode.glsl"
uniform sampler2D u_frame;
uniform sampler2D u_reference;
uniform sampler2D u_heat;
uniform int u_split;
uniform int u_overlay;
uniform int u_height;
out vec4 out_color;
const float kOverlayDim = 0.4;  // the frame under the overlay where there is no error to show
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 q = ivec2(p.x, u_height - 1 - p.y);
  vec3 c = texelFetch(u_frame, p, 0).rgb;
  vec3 mode = srgbEncode(c);
  vec3 outc;
  if (p.x >= u_split) {
    vec4 r = texelFetch(u_reference, q, 0);
    outc = r.a > 0.5 ? r.rgb : 0.5 * mode;
  } else if (u_overlay != 0) {
    vec4 h = texelFetch(u_heat, q, 0);
    outc = h.a > 0.5 ? h.rgb : kOverlayDim * mode;
  } else {
    outc = mode;
  }
  if (p.x == u_split - 1 && u_split < textureSize(u_frame, 0).x) outc = vec3(1.0);
  out_color = vec4(outc, 1.0);
})";

unsigned makeTexture(int width, int height) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);  // cleared after
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, 0);
  return t;
}

// Clears `texture` to 0 (alpha 0: nothing traced, no error) by drawing, not by uploading zeros: at the start of a
// reference the window's thread only queues it.
void clearTexture(unsigned framebuffer, unsigned texture) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  glDisable(GL_SCISSOR_TEST);
  const GLfloat zero[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, zero);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// The wipe's program: its fragment shader here, the encode it includes from the embedded shaders.
gl::Program wipeProgram() {
  const gl::ShaderFileLookup lookup = [](const std::string& name) {
    return name == "wipe.frag" ? std::string(kWipeFs) : gl::shaderSource(name);
  };
  gl::Program p = gl::Program::fromSources({"full-screen triangle (app/view/window.cpp)", kFullScreenVs},
                                           gl::shaderWithIncludes("wipe.frag", lookup));
  PresentPass::bindBlockOf(p.id());
  return p;
}

}  // namespace

Wipe::Wipe(Window& window) : window_(window), program_(wipeProgram()) {}

Wipe::~Wipe() {
  window_.context().makeCurrent();
  if (reference_) glDeleteTextures(1, &reference_);
  if (heat_) glDeleteTextures(1, &heat_);
  if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
}

void Wipe::reset(int width, int height) {
  if (!framebuffer_) glGenFramebuffers(1, &framebuffer_);
  if (width != width_ || height != height_ || !reference_) {
    if (reference_) glDeleteTextures(1, &reference_);
    if (heat_) glDeleteTextures(1, &heat_);
    width_ = width;
    height_ = height;
    reference_ = makeTexture(width, height);
    heat_ = makeTexture(width, height);
  }
  clearTexture(framebuffer_, reference_);
  clearTexture(framebuffer_, heat_);
  gl::checkGlError("creating the wipe's textures");
}

void Wipe::uploadTiles(const std::vector<TileRect>& tiles, const std::vector<std::uint8_t>& rgba) {
  if (tiles.empty()) return;
  glBindTexture(GL_TEXTURE_2D, reference_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, width_);
  for (const TileRect& t : tiles) {
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, t.x0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, t.y0);
    glTexSubImage2D(GL_TEXTURE_2D, 0, t.x0, t.y0, t.x1 - t.x0, t.y1 - t.y0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
  glBindTexture(GL_TEXTURE_2D, 0);
  gl::checkGlError("uploading the reference's tiles");
}

void Wipe::uploadHeat(const std::vector<std::uint8_t>& rgba) {
  glBindTexture(GL_TEXTURE_2D, heat_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glBindTexture(GL_TEXTURE_2D, 0);
  gl::checkGlError("uploading the error heat map");
}

void Wipe::present(unsigned frame, int width, int height, double split_px, bool overlay) {
  beginPresentPass(width, height);
  program_.use();
  const unsigned textures[3] = {frame, reference_, heat_};
  const char* names[3] = {"u_frame", "u_reference", "u_heat"};
  for (int k = 0; k < 3; ++k) {
    glActiveTexture(GLenum(GL_TEXTURE0 + k));
    glBindTexture(GL_TEXTURE_2D, textures[k]);
    program_.set(names[k], k);
  }
  glActiveTexture(GL_TEXTURE0);
  window_.presentPass().bindTable();
  program_.set("u_split", int(split_px + 0.5));
  program_.set("u_overlay", overlay ? 1 : 0);
  program_.set("u_height", height);
  glBindVertexArray(window_.emptyVertexArray());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  gl::checkGlError("presenting the wipe");
}

}  // namespace pvrr::app::view

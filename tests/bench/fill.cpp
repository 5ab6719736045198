// The backend's floor for a 1280 x 720 frame: a depth clear, an optional colour clear and one full-screen quad
// into a colour + 32-bit float depth target, either with a constant colour (*_fill) or with three bilinear reads
// of a 1024^2 map (*_fetch3_<map format>: a dispersive lens's three texture-coordinate sets over the whole
// screen; *_fetch3_r32f_planes: one read from each of three R32F planes, as a lens with RGB dispersion
// reads its map). These figures chose the first-pass map formats (RGBA32F: llvmpipe filters it faster than
// RGBA16F; R32F planes for RGB lenses), the picture-only frame target (RGBA16: written faster than RGBA32F,
// *_fill_no_colour_clear) and dropped the colour clears (the sky covers every pixel).
// Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include "pvrr/gl/context.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/program.h"

namespace {

using namespace pvrr::gl;

const char* kVertex = R"(#version 330 core
layout(location = 0) in vec2 a_ndc;
out vec2 v_uv;
void main() { v_uv = 0.5 * a_ndc + 0.5; gl_Position = vec4(a_ndc, 0.5, 1.0); })";
const char* kConstant = R"(#version 330 core
in vec2 v_uv;
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(0.3, 0.4, 0.5, 1.0); })";
const char* kThreeReads = R"(#version 330 core
in vec2 v_uv;
uniform sampler2D u_map;
layout(location = 0) out vec4 o_color;
void main() {
  o_color = vec4(texture(u_map, v_uv).rgb + texture(u_map, 0.99 * v_uv).rgb + texture(u_map, 0.98 * v_uv).rgb, 1.0);
})";

const char* kPlaneReads = R"(#version 330 core
in vec2 v_uv;
uniform sampler2D u_r, u_g, u_b;
layout(location = 0) out vec4 o_color;
void main() {
  o_color = vec4(texture(u_r, v_uv).r, texture(u_g, 0.99 * v_uv).r, texture(u_b, 0.98 * v_uv).r, 1.0);
})";

enum class Shader { Constant, ThreeReads, PlaneReads };

void BM_Frame(benchmark::State& state, ColorFormat target, ColorFormat map_format, Shader shader, bool clear_colour) {
  auto ctx = GlContext::create(glBackendFromEnvironment(GlBackend::Auto));
  Framebuffer frame(1280, 720, {target}, DepthFormat::Depth32F);
  // Planes: three R32F textures on units 1-3 (map_format is then ignored).
  const std::vector<ColorFormat> formats = shader == Shader::PlaneReads
                                               ? std::vector<ColorFormat>{ColorFormat::R32F, ColorFormat::R32F, ColorFormat::R32F}
                                               : std::vector<ColorFormat>{map_format};
  Framebuffer map(1024, 1024, formats, DepthFormat::None);
  for (int i = 0; i < map.colorCount(); ++i) {
    glActiveTexture(GLenum(GL_TEXTURE0 + (shader == Shader::PlaneReads ? i + 1 : 0)));
    glBindTexture(GL_TEXTURE_2D, map.colorTexture(i));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  glActiveTexture(GL_TEXTURE0);
  const char* fragment = shader == Shader::Constant ? kConstant : shader == Shader::ThreeReads ? kThreeReads : kPlaneReads;
  const Program program = Program::fromSources({"fill.vert", kVertex}, {"fill.frag", fragment});
  GLuint vao = 0, vbo = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  const float quad[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  if (target == ColorFormat::SRGB8A8) glEnable(GL_FRAMEBUFFER_SRGB);
  frame.bind();
  program.use();
  program.set("u_map", 0);
  program.set("u_r", 1);
  program.set("u_g", 2);
  program.set("u_b", 3);
  for (auto _ : state) {
    const float zero[4] = {0, 0, 0, 0}, far_depth = 1.0f;
    if (clear_colour) glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glFinish();
  }
  glDisable(GL_FRAMEBUFFER_SRGB);
  glDeleteBuffers(1, &vbo);
  glDeleteVertexArrays(1, &vao);
  state.SetLabel(ctx->backendName() + " " + ctx->glRenderer());
}

#define PVRR_FRAME(name, target, map, shader, clear)                                                             \
  BENCHMARK_CAPTURE(BM_Frame, name, ColorFormat::target, ColorFormat::map, Shader::shader, clear)                 \
      ->Unit(benchmark::kMillisecond)                                                                            \
      ->UseRealTime();
PVRR_FRAME(rgba32f_fill, RGBA32F, RGBA8, Constant, true)
PVRR_FRAME(rgba32f_fill_no_colour_clear, RGBA32F, RGBA8, Constant, false)
PVRR_FRAME(rgba16f_fill, RGBA16F, RGBA8, Constant, true)
PVRR_FRAME(rgba8_fill, RGBA8, RGBA8, Constant, true)
PVRR_FRAME(rgba16_fill_no_colour_clear, RGBA16, RGBA8, Constant, false)
PVRR_FRAME(rgba8_fill_no_colour_clear, RGBA8, RGBA8, Constant, false)
PVRR_FRAME(srgb8_fill, SRGB8A8, RGBA8, Constant, true)
PVRR_FRAME(rgba32f_fetch3_rgba16f, RGBA32F, RGBA16F, ThreeReads, false)
PVRR_FRAME(rgba32f_fetch3_rgba32f, RGBA32F, RGBA32F, ThreeReads, false)
PVRR_FRAME(rgba32f_fetch3_rgba8, RGBA32F, RGBA8, ThreeReads, false)
PVRR_FRAME(rgba32f_fetch3_srgb8, RGBA32F, SRGB8A8, ThreeReads, false)
PVRR_FRAME(rgba32f_fetch3_r32f_planes, RGBA32F, R32F, PlaneReads, false)

}  // namespace

BENCHMARK_MAIN();

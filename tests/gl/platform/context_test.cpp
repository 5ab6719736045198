// Headless GL contexts (OSMesa and EGL), programs and framebuffers: a known scene is rendered into an FBO of
// explicit size, read back and compared with an image computed analytically from the triangle's vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "pvrr/base/error.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/gl.h"  // test-only: glad for drawing and glGetTexImage
#include "pvrr/gl/program.h"
#include "pvrr/base/image.h"

namespace pvrr::gl {
namespace {

// Framebuffer size: not square and not a power of two, so a swapped width/height or row order shows.
constexpr int kWidth = 64;
constexpr int kHeight = 48;
// The triangle, counter-clockwise in normalised device coordinates (x, y pairs).
constexpr std::array<float, 6> kTriangleNdc = {-0.7f, -0.8f, 0.8f, -0.5f, -0.2f, 0.9f};
// Colours chosen so that c * 255 is an integer: the RGBA8 value is then exact, not a rounding tie.
constexpr std::array<float, 4> kClearColor = {0.2f, 0.4f, 0.6f, 1.0f};     // 51, 102, 153
constexpr std::array<float, 4> kTriangleColor = {0.8f, 0.2f, 0.0f, 1.0f};  // 204, 51, 0
// Written by the fragment shader into attachment 1's blue channel; exactly representable.
constexpr float kFragmentValue = 0.375f;
// GL converts floats to 8-bit unsigned normalised values by rounding; an implementation may be off by one code.
constexpr int kCodeTolerance = 1;
// Pixel centres closer than this to a triangle edge are not checked: which side they fall on depends on the
// rasteriser's sub-pixel vertex snapping (1/256 px on llvmpipe) and tie rules, and 1 px is far beyond both.
constexpr double kEdgeMarginPx = 1.0;

std::uint8_t code(float c) { return static_cast<std::uint8_t>(std::lround(c * 255.0f)); }

// Signed distance in pixels from window point (x, y) to the edges of the triangle in window coordinates
// (origin bottom-left); positive inside. The minimum over the three edges.
double insideDistancePx(double x, double y) {
  double wx[3], wy[3];
  for (int k = 0; k < 3; ++k) {
    wx[k] = (kTriangleNdc[2 * k] + 1.0) * 0.5 * kWidth;
    wy[k] = (kTriangleNdc[2 * k + 1] + 1.0) * 0.5 * kHeight;
  }
  double d = 1e300;
  for (int k = 0; k < 3; ++k) {
    const int n = (k + 1) % 3;
    const double ex = wx[n] - wx[k], ey = wy[n] - wy[k];
    // Counter-clockwise vertices: the interior is to the left of each edge.
    d = std::min(d, (ex * (y - wy[k]) - ey * (x - wx[k])) / std::hypot(ex, ey));
  }
  return d;
}

// Pixel (column x, top-down row r): its centre in GL window coordinates is (x + 0.5, kHeight - 1 - r + 0.5).
double insideDistanceOfPixel(int x, int r) { return insideDistancePx(x + 0.5, kHeight - 1 - r + 0.5); }

// A vertex array with one buffer of 2D positions at attribute 0 (test-only geometry).
class TriangleMesh {
 public:
  explicit TriangleMesh(const std::array<float, 6>& xy) {
    glGenVertexArrays(1, &vao_);
    glBindVertexArray(vao_);
    glGenBuffers(1, &vbo_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_);
    glBufferData(GL_ARRAY_BUFFER, sizeof(float) * xy.size(), xy.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
    glBindVertexArray(0);
  }
  ~TriangleMesh() {
    glDeleteBuffers(1, &vbo_);
    glDeleteVertexArrays(1, &vao_);
  }
  TriangleMesh(const TriangleMesh&) = delete;
  TriangleMesh& operator=(const TriangleMesh&) = delete;
  void draw() const {
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
  }

 private:
  GLuint vao_ = 0, vbo_ = 0;
};

struct Rendered {
  ImageRGB8 color;            // attachment 0 (RGBA8), alpha dropped
  std::vector<float> coords;  // attachment 1 (RGBA32F): gl_FragCoord.xy, kFragmentValue, 1 inside the triangle
};

// Renders the known scene with the context current now. Checks for GL errors after each pass.
Rendered renderScene(const std::vector<std::string>& defines = {}) {
  Framebuffer fbo(kWidth, kHeight, {ColorFormat::RGBA8, ColorFormat::RGBA32F}, DepthFormat::Depth24);
  Program program("test_triangle.vert", "test_triangle.frag", defines);
  fbo.clear(kClearColor);
  checkGlError("clear pass");
  {
    TriangleMesh mesh(kTriangleNdc);
    glDisable(GL_DEPTH_TEST);
    program.set("u_color", glm::vec4(kTriangleColor[0], kTriangleColor[1], kTriangleColor[2], kTriangleColor[3]));
    program.set("u_value", kFragmentValue);
    fbo.bind();
    mesh.draw();
    checkGlError("triangle pass");
  }
  Rendered out;
  out.color = rgbFromRgba(kWidth, kHeight, fbo.readRGBA8(0));
  out.coords = fbo.readFloat4(1);
  checkGlError("readback");
  return out;
}

// Compares a rendering with the analytic expectation; returns the number of pixels checked.
int expectMatchesAnalytic(const Rendered& r, const std::array<std::uint8_t, 3>& inside_rgb, const std::string& who) {
  const std::array<std::uint8_t, 3> outside_rgb = {code(kClearColor[0]), code(kClearColor[1]), code(kClearColor[2])};
  int checked = 0, inside = 0, bad_color = 0, bad_coords = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double d = insideDistanceOfPixel(x, y);
      if (std::abs(d) < kEdgeMarginPx) continue;
      ++checked;
      const bool in = d > 0;
      inside += in;
      const auto& want = in ? inside_rgb : outside_rgb;
      const std::uint8_t* got = r.color.at(x, y);
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int(got[c]) - int(want[c])) > kCodeTolerance) {
          if (++bad_color <= 5) {
            ADD_FAILURE() << who << ": pixel (" << x << ", row " << y << ") channel " << c << " = " << int(got[c])
                          << ", expected " << int(want[c]) << (in ? " (inside)" : " (outside)");
          }
        }
      }
      // Attachment 1: inside, the fragment's own window coordinates, which also checks the top-down row order.
      const float* v = &r.coords[4 * (static_cast<std::size_t>(y) * kWidth + x)];
      const std::array<float, 4> want_v =
          in ? std::array<float, 4>{x + 0.5f, kHeight - 1 - y + 0.5f, kFragmentValue, 1.0f} : kClearColor;
      for (int c = 0; c < 4; ++c) {
        if (v[c] != want_v[c] && ++bad_coords <= 5) {
          ADD_FAILURE() << who << ": RGBA32F pixel (" << x << ", row " << y << ") component " << c << " = " << v[c]
                        << ", expected " << want_v[c];
        }
      }
    }
  }
  EXPECT_EQ(bad_color, 0) << who;
  EXPECT_EQ(bad_coords, 0) << who;
  // The triangle covers about a third of the frame; both classes must be well represented.
  EXPECT_GT(inside, kWidth * kHeight / 5) << who;
  EXPECT_GT(checked - inside, kWidth * kHeight / 5) << who;
  return checked;
}

// Pixels whose centres lie within kEdgeMarginPx of an edge (where two correct rasterisers may disagree).
int edgeBandPixels() {
  int n = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) n += std::abs(insideDistanceOfPixel(x, y)) < kEdgeMarginPx;
  }
  return n;
}

std::array<std::uint8_t, 3> triangleCodes() {
  return {code(kTriangleColor[0]), code(kTriangleColor[1]), code(kTriangleColor[2])};
}

// Creates a context of `backend`, or skips (with the reason) where none can exist at all. PVRR_TEST_REQUIRE_GL=1
// turns the skip into a failure (on machines known to have both backends).
std::unique_ptr<GlContext> createOrSkip(GlBackend backend, std::string* skip_reason) {
  try {
    return GlContext::create(backend);
  } catch (const Error& e) {
    const char* require = std::getenv("PVRR_TEST_REQUIRE_GL");
    if (require != nullptr && std::string(require) == "1") {
      ADD_FAILURE() << "PVRR_TEST_REQUIRE_GL=1 but: " << e.what();
    }
    *skip_reason = std::string("no ") + glBackendName(backend) + " GL context can be created here: " + e.what();
    return nullptr;
  }
}

#define PVRR_CREATE_OR_SKIP(var, backend)            \
  std::string var##_skip;                             \
  auto var = createOrSkip(backend, &var##_skip);      \
  if (!var) GTEST_SKIP() << var##_skip;

void report(const GlContext& c) {
  std::cout << "[ context  ] " << c.backendName() << ": GL_VERSION \"" << c.glVersion() << "\", GL_RENDERER \""
            << c.glRenderer() << "\", GLSL " << c.glslVersion() << (c.isHardware() ? ", hardware" : ", software")
            << "\n";
}

TEST(GlBackend, ParsesTheThreeNamesAndListsThemOnError) {
  EXPECT_EQ(parseGlBackend("auto"), GlBackend::Auto);
  EXPECT_EQ(parseGlBackend("egl"), GlBackend::Egl);
  EXPECT_EQ(parseGlBackend("osmesa"), GlBackend::OsMesa);
  for (auto b : {GlBackend::Auto, GlBackend::Egl, GlBackend::OsMesa}) EXPECT_EQ(parseGlBackend(glBackendName(b)), b);
  try {
    parseGlBackend("EGL");
    FAIL() << "upper-case name accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("auto, egl, osmesa"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\"EGL\""), std::string::npos) << e.what();
  }
}

TEST(GlBackend, EnvironmentOverridesTheFallbackAndNamesTheVariableOnError) {
  const char* saved = std::getenv("PVRR_GL");
  const std::string saved_value = saved ? saved : "";
  unsetenv("PVRR_GL");
  EXPECT_EQ(glBackendFromEnvironment(GlBackend::OsMesa), GlBackend::OsMesa);
  setenv("PVRR_GL", "", 1);
  EXPECT_EQ(glBackendFromEnvironment(GlBackend::Egl), GlBackend::Egl);
  setenv("PVRR_GL", "osmesa", 1);
  EXPECT_EQ(glBackendFromEnvironment(GlBackend::Auto), GlBackend::OsMesa);
  setenv("PVRR_GL", "vulkan", 1);
  try {
    glBackendFromEnvironment();
    FAIL() << "PVRR_GL=vulkan accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("PVRR_GL"), std::string::npos) << e.what();
  }
  if (saved) {
    setenv("PVRR_GL", saved_value.c_str(), 1);
  } else {
    unsetenv("PVRR_GL");
  }
}

TEST(GlContext, RejectsAVersionBelowTheFloor) { EXPECT_THROW(GlContext::create(GlBackend::OsMesa, 2, 1), Error); }

TEST(GlContext, OsMesaRendersTheAnalyticTriangle) {
  PVRR_CREATE_OR_SKIP(context, GlBackend::OsMesa);
  report(*context);
  EXPECT_EQ(context->backendName(), "osmesa");
  EXPECT_FALSE(context->isHardware());
  EXPECT_GE(context->glMajor() * 10 + context->glMinor(), 33) << context->glVersion();
  EXPECT_NE(context->glVersion().find("Core Profile"), std::string::npos) << context->glVersion();
  EXPECT_EQ(GlContext::current(), context.get());
  EXPECT_EQ(context->creationNotes(), "");
  expectMatchesAnalytic(renderScene(), triangleCodes(), "osmesa");
}

TEST(GlContext, EglRendersTheAnalyticTriangle) {
  PVRR_CREATE_OR_SKIP(context, GlBackend::Egl);
  report(*context);
  const std::set<std::string> egl_names = {"egl-device", "egl-device-software", "egl-surfaceless"};
  EXPECT_TRUE(egl_names.count(context->backendName())) << context->backendName();
  if (context->backendName() != "egl-device") {
    EXPECT_FALSE(context->isHardware());
    // A software EGL path is taken only after the hardware-device path failed, and the notes say why.
    EXPECT_NE(context->creationNotes().find("EGL device (hardware)"), std::string::npos) << context->creationNotes();
  }
  EXPECT_GE(context->glMajor() * 10 + context->glMinor(), 33) << context->glVersion();
  expectMatchesAnalytic(renderScene(), triangleCodes(), context->backendName());
}

TEST(GlContext, OsMesaThenEglInOneProcessGiveTheSameImage) {
  Rendered osmesa, egl;
  {
    PVRR_CREATE_OR_SKIP(context, GlBackend::OsMesa);
    osmesa = renderScene();
  }
  EXPECT_EQ(GlContext::current(), nullptr);
  {
    PVRR_CREATE_OR_SKIP(context, GlBackend::Egl);
    egl = renderScene();
  }
  // Both are checked against the analytic image away from edges; along edges two correct rasterisers may
  // differ (llvmpipe against a GPU), so at most the edge band may disagree, and by no more than a full step.
  const ImageDiff diff = compareImages(osmesa.color, egl.color, kCodeTolerance);
  const double max_edge_fraction = static_cast<double>(edgeBandPixels()) / (kWidth * kHeight);
  EXPECT_LE(diff.failing_fraction, max_edge_fraction) << describe(diff);
  std::cout << "[ compare  ] osmesa vs egl: " << describe(diff) << "\n";
}

TEST(GlContext, TwoLiveContextsSwitchWithMakeCurrent) {
  PVRR_CREATE_OR_SKIP(a, GlBackend::OsMesa);
  // Each context keeps its own framebuffer; switching must reload the entry points and keep the contents.
  Framebuffer fbo_a(8, 4, {ColorFormat::RGBA8}, DepthFormat::None);
  fbo_a.clear({1.0f, 0.0f, 0.0f, 1.0f});
  PVRR_CREATE_OR_SKIP(b, GlBackend::Egl);
  EXPECT_EQ(GlContext::current(), b.get());
  {
    Framebuffer fbo_b(8, 4, {ColorFormat::RGBA8}, DepthFormat::None);
    fbo_b.clear({0.0f, 0.0f, 1.0f, 1.0f});
    // An object of the other context is refused rather than silently used with the wrong names.
    EXPECT_THROW(fbo_a.bind(), Error);
    a->makeCurrent();
    EXPECT_EQ(GlContext::current(), a.get());
    const auto pixels_a = fbo_a.readRGBA8();
    EXPECT_EQ(pixels_a[0], 255);
    EXPECT_EQ(pixels_a[2], 0);
    expectMatchesAnalytic(renderScene(), triangleCodes(), "osmesa after switching");
    b->makeCurrent();
    const auto pixels_b = fbo_b.readRGBA8();
    EXPECT_EQ(pixels_b[0], 0);
    EXPECT_EQ(pixels_b[2], 255);
    expectMatchesAnalytic(renderScene(), triangleCodes(), "egl after switching");
  }
  a->makeCurrent();  // fbo_a is deleted in its own context
}

TEST(GlContext, FallsBackToTheFloorWhenTheRequestedVersionIsUnavailable) {
  // GL 9.9 exists nowhere, so creation must succeed through the 3.3 core fallback.
  PVRR_CREATE_OR_SKIP(context, GlBackend::OsMesa);
  context.reset();
  auto fallback = GlContext::create(GlBackend::OsMesa, 9, 9);
  EXPECT_GE(fallback->glMajor() * 10 + fallback->glMinor(), 33);
  EXPECT_NE(fallback->creationNotes().find("OSMesa, GL 9.9 core"), std::string::npos) << fallback->creationNotes();
}

// ---- programs ----

class GlFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = createOrSkip(glBackendFromEnvironment(GlBackend::Auto), &skip_);
    if (!context_) GTEST_SKIP() << skip_;
  }
  std::string skip_;
  std::unique_ptr<GlContext> context_;
};

TEST(ProgramSource, UnknownShaderNameListsTheAvailableOnes) {
  EXPECT_NE(shaderSource("test_triangle.vert").find("#version"), std::string::npos);
  try {
    shaderSource("no_such.frag");
    FAIL() << "unknown shader accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no_such.frag"), std::string::npos) << m;
    EXPECT_NE(m.find("test_triangle.vert"), std::string::npos) << m;
    EXPECT_NE(m.find("test_triangle.frag"), std::string::npos) << m;
  }
}

TEST(ProgramSource, DefinesGoRightAfterTheVersionLineWithTheLineNumbersKept) {
  const std::string src = "// comment\n#version 330 core\nvoid main() {}\n";
  EXPECT_EQ(insertDefines(src, {"#define A 1", "B 2"}),
            "// comment\n#version 330 core\n#define A 1\n#define B 2\n#line 3\nvoid main() {}\n");
  EXPECT_EQ(insertDefines(src, {}), src);
  EXPECT_EQ(insertDefines("void main() {}\n", {"C"}), "#define C\n#line 1\nvoid main() {}\n");
}

TEST_F(GlFixture, DefinesSelectAShaderVariant) {
  const auto swapped = std::array<std::uint8_t, 3>{code(kTriangleColor[2]), code(kTriangleColor[1]),
                                                   code(kTriangleColor[0])};
  expectMatchesAnalytic(renderScene({"PVRR_TEST_SWAP_RED_BLUE 1"}), swapped, "variant");
}

TEST_F(GlFixture, CompileErrorNamesTheFileAndCarriesTheLog) {
  const ShaderSource vert{"test_triangle.vert", shaderSource("test_triangle.vert")};
  const ShaderSource broken{"broken_test.frag", "#version 330 core\nout vec4 o;\nvoid main() { o = vec4(1.0) }\n"};
  try {
    Program::fromSources(vert, broken);
    FAIL() << "broken shader compiled";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken_test.frag"), std::string::npos) << m;
    EXPECT_NE(m.find("compile"), std::string::npos) << m;
    EXPECT_NE(m.find("error"), std::string::npos) << "no info log in: " << m;
  }
  const ShaderSource broken_vert{"broken_test.vert", "#version 330 core\nvoid main() { gl_Position = 1.0; }\n"};
  try {
    Program::fromSources(broken_vert, {"test_triangle.frag", shaderSource("test_triangle.frag")}, {"X 1"});
    FAIL() << "broken vertex shader compiled";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken_test.vert"), std::string::npos) << m;
    EXPECT_NE(m.find("X 1"), std::string::npos) << "defines missing from: " << m;
  }
  checkGlError("failed builds");  // a failed build leaves no GL error behind
}

TEST_F(GlFixture, LinkErrorNamesBothFiles) {
  const ShaderSource vert{"test_triangle.vert", shaderSource("test_triangle.vert")};
  // Compiles (a shader may be one of several of its stage) but cannot link: the stage has no main().
  const ShaderSource frag{"no_main.frag", "#version 330 core\nout vec4 o;\nvoid helper() { o = vec4(1.0); }\n"};
  try {
    Program::fromSources(vert, frag);
    FAIL() << "fragment stage without main() linked";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test_triangle.vert + no_main.frag"), std::string::npos) << m;
    EXPECT_NE(m.find("link"), std::string::npos) << m;
  }
}

TEST_F(GlFixture, UniformLocationsAreCachedAndInactiveOnesIgnored) {
  Program program("test_triangle.vert", "test_triangle.frag");
  const int loc = program.uniformLocation("u_color");
  EXPECT_GE(loc, 0);
  EXPECT_EQ(program.uniformLocation("u_color"), loc);
  EXPECT_FALSE(program.hasUniform("u_not_declared"));
  program.set("u_not_declared", 1.0f);  // ignored, like GL's location -1
  program.set("u_value", 0.5f);
  float value = 0;
  glGetUniformfv(program.id(), program.uniformLocation("u_value"), &value);
  EXPECT_EQ(value, 0.5f);
  checkGlError("uniform setters");
}

TEST_F(GlFixture, CheckGlErrorNamesTheErrorAndThePlace) {
  glEnable(0xFFFFu);  // not a capability: GL_INVALID_ENUM
  try {
    checkGlError("a deliberate bad enum");
    FAIL() << "GL error not reported";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("GL_INVALID_ENUM"), std::string::npos) << m;
    EXPECT_NE(m.find("a deliberate bad enum"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(checkGlError("after draining"));
}

// ---- framebuffers and textures ----

TEST_F(GlFixture, FramebufferRejectsBadSizesAndAttachments) {
  EXPECT_THROW(Framebuffer(0, 4, {ColorFormat::RGBA8}), Error);
  EXPECT_THROW(Framebuffer(4, -1, {ColorFormat::RGBA8}), Error);
  EXPECT_THROW(Framebuffer(1 << 20, 4, {ColorFormat::RGBA8}), Error);
  Framebuffer fbo(4, 2, {ColorFormat::RGBA16F}, DepthFormat::Depth32F);
  EXPECT_THROW(fbo.readRGBA8(1), Error);
  EXPECT_NE(fbo.depthTexture(), 0u);
  // RGBA16F holds 0.375 and 0.25 exactly (binary fractions with few bits).
  fbo.clear({0.375f, 0.25f, 1.0f, 0.5f});
  const auto v = fbo.readFloat4(0);
  ASSERT_EQ(v.size(), 4u * 4 * 2);
  EXPECT_EQ(v[0], 0.375f);
  EXPECT_EQ(v[1], 0.25f);
  EXPECT_EQ(v[3], 0.5f);
  checkGlError("RGBA16F framebuffer");
}

TEST_F(GlFixture, Texture2DIsUploadedBottomRowFirstWithMipmaps) {
  ImageRGB8 image(3, 2);  // odd width: RGB8 rows of 9 bytes, stored as RGBA8
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<std::uint8_t>(10 * i + 1);
  Texture texture = createTexture2D(image, TextureEncoding::Linear, true);
  texture.bind(0);
  std::vector<std::uint8_t> level0(image.rgb.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTexImage(GL_TEXTURE_2D, 0, GL_RGB, GL_UNSIGNED_BYTE, level0.data());
  // GL row 0 (t = 0) is the image's bottom row.
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(level0[3 * ((1 - y) * 3 + x) + c], image.at(x, y)[c]) << x << "," << y << "," << c;
      }
    }
  }
  GLint level1_width = 0;
  glGetTexLevelParameteriv(GL_TEXTURE_2D, 1, GL_TEXTURE_WIDTH, &level1_width);
  EXPECT_EQ(level1_width, 1);  // floor(3 / 2)
  checkGlError("createTexture2D");
}

TEST_F(GlFixture, CubeMapFacesKeepTheirOrderAndRows) {
  std::array<ImageRGB8, 6> faces;
  for (int f = 0; f < 6; ++f) {
    faces[f] = ImageRGB8(2, 2);
    for (std::size_t i = 0; i < faces[f].rgb.size(); ++i) faces[f].rgb[i] = static_cast<std::uint8_t>(40 * f + i);
  }
  Texture cube = createCubeMap(faces, TextureEncoding::Linear, false);
  cube.bind(0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  for (int f = 0; f < 6; ++f) {
    std::vector<std::uint8_t> got(12);
    glGetTexImage(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_RGB, GL_UNSIGNED_BYTE, got.data());
    EXPECT_EQ(got, faces[f].rgb) << "face " << f;
  }
  faces[5] = ImageRGB8(2, 3);
  EXPECT_THROW(createCubeMap(faces), Error);
  checkGlError("createCubeMap");
}

}  // namespace
}  // namespace pvrr::gl

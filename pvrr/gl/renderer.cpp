#include "pvrr/gl/renderer.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>

#include "pvrr/base/error.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/program.h"
#include "pvrr/base/format.h"
#include "pvrr/impostor/lens_height_map.h"
#include "pvrr/method/map_footprint.h"
#include "pvrr/impostor/surface_map.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr::gl {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

glm::mat4 toFloat(const Mat4& m) { return glm::mat4(m); }

// The projection * view of a camera whose origin is `origin`, acting on points relative to that origin.
// The view's translation is folded in double precision, so nothing large reaches float.
Mat4 relativeViewProj(const Mat4& proj, const Mat4& view, const Vec3& origin) {
  return proj * view * glm::translate(Mat4(1.0), origin);
}

// Cube-map render target for the envmap baseline (Framebuffer covers the 2D targets): N colour cube maps
// and a depth buffer; selectFace() attaches one face of each.
struct CubeTarget {
  GLuint fbo = 0, depth = 0;
  std::vector<GLuint> colors;
  int size = 0;
  CubeTarget() = default;
  CubeTarget(const CubeTarget&) = delete;
  CubeTarget& operator=(const CubeTarget&) = delete;
  ~CubeTarget() { release(); }
  void release() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (depth) glDeleteRenderbuffers(1, &depth);
    if (!colors.empty()) glDeleteTextures(GLsizei(colors.size()), colors.data());
    fbo = depth = 0;
    colors.clear();
  }
  void create(int n, const std::vector<GLenum>& formats) {
    release();
    size = n;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    colors.resize(formats.size());
    glGenTextures(GLsizei(colors.size()), colors.data());
    for (size_t i = 0; i < formats.size(); ++i) {
      glBindTexture(GL_TEXTURE_CUBE_MAP, colors[i]);
      for (int f = 0; f < 6; ++f)
        glTexImage2D(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), 0, GLint(formats[i]), n, n, 0, GL_RGBA, GL_FLOAT, nullptr);
      // Colour, seen points (and the normals and indices of impostor mode's elements) filter linearly (see the
      // 2D maps below; followCubes decodes the blended index).
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    }
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, n, n);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    selectFace(0);
    std::vector<GLenum> bufs(formats.size());
    for (size_t i = 0; i < bufs.size(); ++i) bufs[i] = GLenum(GL_COLOR_ATTACHMENT0 + i);
    glDrawBuffers(GLsizei(bufs.size()), bufs.data());
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      throw Error("GL: cube-map framebuffer " + std::to_string(n) + "^2 incomplete (status " + std::to_string(status) + ")");
    checkGlError("creating a cube-map target");
  }
  // Binds the target with `face` attached, sets the viewport and clears it.
  void selectFace(int face) const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    for (size_t i = 0; i < colors.size(); ++i)
      glFramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face),
                             colors[i], 0);
    glViewport(0, 0, size, size);
    const float zero[4] = {0, 0, 0, 0}, far_depth = 1.0f;
    for (size_t i = 0; i < colors.size(); ++i) glClearBufferfv(GL_COLOR, GLint(i), zero);
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
  }
};

struct MeshBuffers {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei count = 0;
  void release() {
    if (ebo) glDeleteBuffers(1, &ebo);
    if (vbo) glDeleteBuffers(1, &vbo);
    if (vao) glDeleteVertexArrays(1, &vao);
    vao = vbo = ebo = 0;
  }
};

// Interleaved float attributes: `layout` lists each attribute's component count, in location order.
void uploadMesh(MeshBuffers& mb, const std::vector<float>& data, const std::vector<int>& layout,
                const std::vector<uint32_t>& indices) {
  if (!mb.vao) {
    glGenVertexArrays(1, &mb.vao);
    glGenBuffers(1, &mb.vbo);
    glGenBuffers(1, &mb.ebo);
  }
  glBindVertexArray(mb.vao);
  glBindBuffer(GL_ARRAY_BUFFER, mb.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mb.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(), GL_DYNAMIC_DRAW);
  int stride = 0;
  for (int c : layout) stride += c;
  size_t offset = 0;
  for (size_t i = 0; i < layout.size(); ++i) {
    glEnableVertexAttribArray(GLuint(i));
    glVertexAttribPointer(GLuint(i), layout[i], GL_FLOAT, GL_FALSE, GLsizei(stride * sizeof(float)),
                          reinterpret_cast<const void*>(offset * sizeof(float)));
    offset += size_t(layout[i]);
  }
  mb.count = GLsizei(indices.size());
  glBindVertexArray(0);
}

void draw(const MeshBuffers& mb) {
  glBindVertexArray(mb.vao);
  glDrawElements(GL_TRIANGLES, mb.count, GL_UNSIGNED_INT, nullptr);
}

// GLSL has no #include: splice `#include "file"` lines with the embedded file (one level, as used).
std::string resolveIncludes(const std::string& src) {
  std::string out;
  size_t pos = 0;
  while (pos < src.size()) {
    size_t eol = src.find('\n', pos);
    if (eol == std::string::npos) eol = src.size();
    const std::string line = src.substr(pos, eol - pos);
    const size_t q1 = line.find('"');
    if (line.rfind("#include", 0) == 0 && q1 != std::string::npos) {
      const size_t q2 = line.find('"', q1 + 1);
      out += shaderSource(line.substr(q1 + 1, q2 - q1 - 1)) + "\n";
    } else {
      out += line + "\n";
    }
    pos = eol + 1;
  }
  return out;
}

Program makeProgram(const std::string& vert, const std::string& frag, const std::vector<std::string>& defines = {}) {
  return Program::fromSources({vert, resolveIncludes(shaderSource(vert))}, {frag, resolveIncludes(shaderSource(frag))},
                              defines);
}

// Element vertices (shaders/element.vert): position, normal, three texture-coordinate sets, three weights,
// the seen point's coordinates, the traced colour of totally reflected vertices (rgb, and 1 where the seen
// channel's is) and their traced seen point.
const std::vector<int> kElementLayout = {3, 3, 3, 3, 3, 3, 3, 3, 3, 4, 3};
constexpr size_t kElementFloats = 34;

// At most this many first passes per frame (top-level and nested): each holds a size^2 colour, seen-point
// and depth target. Elements that would need more are drawn dark in their map, and the stats say so.
constexpr size_t kMaxFirstPasses = 16;

// The map size of an element seen in a map of size `parent`: half of it, at least 128 texels (for both the
// texture and the side rendered). A nested element covers part of its parent's map, which covers part of the
// image, so half the parent's texels still exceed the pixels it covers in the shipped scenes; full-size nested maps (28 MB each at 1024^2 then: RGBA16F
// colour, RGBA32F seen points, 32-bit depth) took the mirror pair's render at 1280 x 720 to 460 MB.
int nestedMapSize(int parent) { return parent <= 128 ? parent : std::max(128, parent / 2); }

}  // namespace

// Each patch's view volume is narrower, so its texels cover a smaller angle. At least 128. An automatic split
// into 16 x 16 patches at full size took 3.3 GB and 14 s a frame.
int patchMapSize(int map_size, size_t patches) {
  if (patches <= 4 || map_size <= 128) return map_size;
  const double shrink = std::ceil(std::sqrt(double(patches) / 4.0));
  return std::max(128, int(double(map_size) / shrink));
}

namespace {
// Patch views a viewer can see (the others render no map).
size_t inView(const ElementFrame& f) {
  return size_t(std::count_if(f.views.begin(), f.views.end(), [](const PatchView& v) { return v.in_view; }));
}
}  // namespace

int topLevelMapSide(const Scene& scene, const ElementFrame& f, const PatchView& pv, const RendererOptions& options) {
  const int size = patchMapSize(options.map_size, std::max<size_t>(1, inView(f)));
  if (!(options.map_texels_per_pixel > 0)) return size;
  const Observer& ob = scene.observer;
  const double pixels = patchScreenPixels(f, pv, ob.visibilityProjection() * ob.view(), ob.width, ob.height);
  return mapSideForPixels(pv.volume, pixels, options.map_texels_per_pixel, size);
}

namespace {

// A camera of one pass (the second pass, or a first pass from a virtual viewpoint): positions are relative
// to `origin`.
struct PassCamera {
  Vec3 origin{0};
  Mat4 view_proj{1.0};   // relativeViewProj: acts on positions relative to origin
  Vec3 rays_from{0};     // where the viewing rays start, relative to origin (0: the camera itself)
  bool reversed_depth = false;
  bool planes = false;   // the target is a lens map in R, G and B planes (shaders/outputs.glsl PLANES)
};

// A serial number for every first pass rendered in the process (FrameCache::maps_serial).
uint64_t nextFirstPassSerial() {
  static std::atomic<uint64_t> serial{0};
  return ++serial;
}

// Whether any part of the convex hull of `points` can be inside the view volume: false only when every
// point lies outside one and the same clip plane (homogeneous outcodes; exact for a convex hull).
bool mayBeInVolume(const std::vector<Vec3>& points, const Mat4& m) {
  unsigned all = 0x3f;
  for (const Vec3& p : points) {
    all &= clipOutcode(m * Vec4(p, 1.0));
    if (!all) return true;
  }
  return all == 0;
}

// A 2D float texture of w x h texels, 1 or 4 floats each, made or replaced in `tex`. The impostor shader
// reads these maps with texelFetch and filters them in float itself (shaders/element.frag `bilinear`):
// nearest, clamped.
void uploadDataTexture(GLuint& tex, GLint internal_format, int w, int h, int channels, const float* data) {
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, internal_format, w, h, 0, channels == 1 ? GL_RED : GL_RGBA, GL_FLOAT, data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, 0);
}

// Binds `textures` to units first, first + 1, ... and names them in `p`; unit 0 active after.
void bindDataTextures(const Program& p, int first, std::initializer_list<std::pair<const char*, GLuint>> textures) {
  int unit = first;
  for (const auto& [name, tex] : textures) {
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_2D, tex);
    p.set(name, unit++);
  }
  glActiveTexture(GL_TEXTURE0);
}

// Cube-map faces in GL order (+X, -X, +Y, -Y, +Z, -Z): view direction and up vector.
const Vec3 kCubeDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const Vec3 kCubeUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};

}  // namespace

struct Renderer::Impl {
  const Scene& scene;
  const RayScene& rays;
  RendererOptions options;
  // A program's defines, plus the scene's light counts (shaders/shading.glsl) and NO_SEEN_POINTS when
  // RendererOptions::seen_points is off, unless the variant writes seen points all the same (kWithSeenPoints:
  // the impostor cube maps, whose seen points are the distances the search reads).
  static constexpr const char* kWithSeenPoints = "#define WITH_SEEN_POINTS";
  std::vector<std::string> defines(std::vector<std::string> d) const {
    int dir = 0, point = 0;
    for (const Light& l : scene.lights) {
      dir += l.type == Light::Type::Directional;
      point += l.type == Light::Type::Point;
    }
    d.push_back("#define NUM_DIR_LIGHTS " + std::to_string(dir));
    d.push_back("#define NUM_POINT_LIGHTS " + std::to_string(point));
    if (!options.seen_points && std::find(d.begin(), d.end(), kWithSeenPoints) == d.end())
      d.push_back("#define NO_SEEN_POINTS");
    return d;
  }
  Program sky_program = makeProgram("sky.vert", "sky.frag", defines({}));
  Program plain_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_PLAIN"}));
  Program envmap_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_ENVMAP"}));
  Program lens_envmap_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_ENVMAP", "#define LENS"}));
  Program pvrr_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_PVRR", "#define CHANNELS 1"}));
  Program pvrr3_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_PVRR", "#define CHANNELS 3"}));
  Program lens_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_PVRR", "#define CHANNELS 1", "#define LENS"}));
  Program lens3_program = makeProgram("element.vert", "element.frag", defines({"#define MODE_PVRR", "#define CHANNELS 3", "#define LENS"}));
  // RGB dispersion: its maps are R, G and B planes.
  Program lens_rgb_program = makeProgram("element.vert", "element.frag",
                                         defines({"#define MODE_PVRR", "#define CHANNELS 3", "#define LENS", "#define RGB_CHANNELS"}));
  // Programs built on demand, by sources and defines: the environment's kinds of mesh that a scene has (built
  // with the renderer), and the variants that draw into a planes map (PLANES, on first use), which only scenes
  // with a lens with RGB dispersion need.
  mutable std::map<std::string, std::unique_ptr<Program>> built_programs;
  const Program& builtProgram(const std::string& vert, const std::string& frag, const std::vector<std::string>& d) const {
    std::string key = vert + " " + frag;
    for (const std::string& x : d) key += "|" + x;
    std::unique_ptr<Program>& p = built_programs[key];
    if (!p) p = std::make_unique<Program>(makeProgram(vert, frag, defines(d)));
    return *p;
  }
  const Program& planesVariant(const std::string& vert, const std::string& frag, std::vector<std::string> d) const {
    d.push_back("#define PLANES");
    return builtProgram(vert, frag, d);
  }
  // Environment meshes (shaders/env.frag): FACETED (one normal per triangle), TEXTURED (a material with a
  // texture; without, no texture is sampled: llvmpipe samples inside a uniform branch all the same).
  // PEEL: the second layer of an impostor's distance map (shaders/outputs.glsl).
  const Program& envProgram(bool faceted, bool textured, bool planes, bool with_seen = false, bool peel = false) const {
    std::vector<std::string> d;
    if (with_seen) d.push_back(kWithSeenPoints);
    if (peel) d.push_back("#define PEEL");
    if (faceted) d.push_back("#define FACETED");
    if (textured) d.push_back("#define TEXTURED");
    if (planes) d.push_back("#define PLANES");
    return builtProgram("env.vert", "env.frag", d);
  }
  // first_layer: an impostor cube's second layer, where nothing lies beyond the first (shaders/sky.frag).
  const Program& skyProgram(bool planes, bool with_seen = false, bool first_layer = false) const {
    if (first_layer)
      return builtProgram("sky.vert", "sky.frag", {kWithSeenPoints, "#define PEEL", "#define FIRST_LAYER"});
    if (with_seen && !options.seen_points) return builtProgram("sky.vert", "sky.frag", {kWithSeenPoints});
    return planes ? planesVariant("sky.vert", "sky.frag", {}) : sky_program;
  }
  // Distance-impostor elements (shaders/element.frag, MODE_IMPOSTOR): a mirror, or a lens with one or three
  // wavelengths; cube_elements > 0: searches that meet a mirror in a cube go on in its cubes (CUBE_ELEMENTS).
  // lens_in_cubes: the scene's one lens is drawn in the other elements' cubes and refracted through there.
  // layers: of each distance map (IMPOSTOR_LAYERS; 2: the second depth-peeled, searched where the first fails).
  // layer_draw, with two layers: 0 the first draw (it discards where it would search them), 1 the second
  // (LAYER_MARCH), 2 the probe between them (LAYER_PROBE: no search; pvrr/gl/renderer.cpp).
  const Program& impostorProgram(bool lens, int channels, int cube_elements, bool lens_in_cubes, int layers,
                                 int layer_draw) const {
    std::vector<std::string> d{"#define MODE_IMPOSTOR",
                               "#define IMPOSTOR_ITERATIONS " + std::to_string(scene.render.impostor_iterations),
                               "#define IMPOSTOR_CHANNELS " + std::to_string(channels),
                               "#define IMPOSTOR_LAYERS " + std::to_string(layers)};
    if (lens) d.push_back("#define LENS");
    if (cube_elements > 0) d.push_back("#define CUBE_ELEMENTS " + std::to_string(cube_elements));
    if (cube_elements > 0 && lens_in_cubes) d.push_back("#define LENS_IN_CUBES");
    if (layer_draw == 1) d.push_back("#define LAYER_MARCH");
    if (layer_draw == 2) d.push_back("#define LAYER_PROBE");
    return builtProgram("element.vert", "element.frag", d);
  }
  // An element drawn into another element's impostor cubes (CUBE_GEOMETRY): a mirror's exact surface point
  // and normal, a lens's mesh point; and its index.
  const Program& cubeGeometryProgram(bool lens, bool peel) const {
    std::vector<std::string> d{"#define MODE_IMPOSTOR", "#define IMPOSTOR_ITERATIONS 0", "#define IMPOSTOR_CHANNELS 1",
                               "#define IMPOSTOR_LAYERS 1", "#define CUBE_GEOMETRY", kWithSeenPoints};
    if (lens) d.push_back("#define LENS");
    if (peel) d.push_back("#define PEEL");
    return builtProgram("element.vert", "element.frag", d);
  }
  const Program& plainProgram(bool planes) const {
    return planes ? planesVariant("element.vert", "element.frag", {"#define MODE_PLAIN"}) : plain_program;
  }
  // A lens with RGB dispersion (three channels of unit R, G and B weights): its maps are planes, its second
  // pass reads one component per channel.
  static bool rgbLens(const Element& el, const ElementFrame& f) {
    if (el.type != ElementType::Lens || f.rays.size() != 3 || f.channels.size() != 3) return false;
    for (size_t c = 0; c < 3; ++c)
      if (channelWeight(f.channels, c) != Vec3(c == 0, c == 1, c == 2)) return false;
    return true;
  }
  Program mask_program = makeProgram("map_mask.vert", "map_mask.frag");
  GLuint empty_vao = 0;
  GLuint mask_vao = 0, mask_vbo = 0;  // closeUnreadTexels' quads
  int max_texture_size = 0;  // GL_MAX_TEXTURE_SIZE
  int max_texture_units = 0;  // GL_MAX_TEXTURE_IMAGE_UNITS
  std::vector<MeshBuffers> env_meshes;
  std::vector<bool> env_faceted;  // per environment mesh: every triangle has one normal at its three corners
  std::vector<bool> env_textured;  // per environment mesh: its material has a texture
  std::vector<std::array<Vec3, 2>> env_bounds;  // per environment mesh: its bounding box, relative to its anchor
  // Closed convex meshes drawn and culled by drawEnvironment, summed over a stage's passes for its note.
  struct CullCount {
    int drawn = 0, culled = 0;
    void add(const CullCount& o) { drawn += o.drawn, culled += o.culled; }
  };
  std::string cullNote(const CullCount& c) const {
    if (c.drawn == 0) return "";
    if (!options.cull_back_faces) return "back faces not culled (off)";
    return "back faces culled on " + std::to_string(c.culled) + " of " + std::to_string(c.drawn) + " closed-mesh draws";
  }
  std::vector<Texture> textures;  // environment textures, in Scene::textures order
  std::unique_ptr<Framebuffer> frame_target;      // the second pass: colour, seen point, surface point
  std::vector<std::unique_ptr<Framebuffer>> maps;  // first-pass maps, one per patch view (reused)
  // The serial of the first pass whose maps this renderer holds (FrameCache::maps_serial): unique in the
  // process (nextFirstPassSerial), so a cache filled by another renderer never matches.
  uint64_t first_pass_serial = 0;
  std::vector<int> map_side;  // per map slot: the longer side its last first pass rendered (MapPass::side)
  std::vector<std::unique_ptr<CubeTarget>> cubes;  // envmap and impostor cubes, one per element
  std::vector<std::unique_ptr<CubeTarget>> cubes1;  // impostor mode's second layers (impostorLayers), one per element
  // Impostor mode: each lens's refractor height maps (pvrr/impostor/lens_height_map.h), built on first use (a lens's
  // shape in its own frame never changes; its pose reaches the shader as u_to_local).
  struct LensMaps {
    GLuint front = 0, back = 0, mask = 0;
    cad::SagSurfacePtr front_surface, back_surface;  // what they were built from (held: never a reused address)
    cad::Outline outline;                            // and the outline of their mask
    LensHeightMap map;
  };
  std::vector<LensMaps> lens_maps;
  // Impostor mode: each mirror's surface maps (pvrr/impostor/surface_map.h: position, derivatives, normal over its
  // parameter domain), built on first use and again if its surface changes.
  struct MirrorMaps {
    std::array<GLuint, 4> textures{};  // position (RGBA32F, w: outline mask), du, dv (RGBA16F), normal (RGBA32F)
    cad::SurfacePtr surface;           // what they were built from (held: never a reused address)
    bool has_outline = false;          // and the outline of their mask
    cad::Outline outline;
    SurfaceMap map;                    // its domain and size; the samples are dropped once uploaded
  };
  std::vector<MirrorMaps> mirror_maps;
  std::vector<MeshBuffers> element_meshes;     // per (element, patch) in pvrr mode; per element otherwise
  ElementGridCache grid_cache;                 // the elements' tessellations, posed anew each frame

  Impl(const Scene& s, const RayScene& r, RendererOptions o) : scene(s), rays(r), options(std::move(o)) {
    glGenVertexArrays(1, &empty_vao);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
    glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_texture_units);
    for (const pvrr::Texture& t : scene.textures) {
      ImageRGB8 image;
      image.width = t.width;
      image.height = t.height;
      image.rgb = t.rgb;
      // sRGB, flipped so v = 0 is the image's bottom row, no mipmaps: bilinear sampling with repeat wrapping,
      // exactly what the tracer does (pvrr/trace/shading.cpp).
      textures.push_back(createTexture2D(image, TextureEncoding::Srgb, false));
      glBindTexture(GL_TEXTURE_2D, textures.back().name());
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    }
    env_meshes.resize(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const EnvMesh& mesh = scene.meshes[m];
      std::vector<float> data;
      data.reserve(mesh.positions.size() * 8);
      for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::vec3 p = mesh.positions[i], n = mesh.normals[i];
        const glm::vec2 uv = mesh.uvs[i];
        data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y});
      }
      std::vector<uint32_t> idx;
      idx.reserve(mesh.triangles.size() * 3);
      for (const auto& t : mesh.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
      uploadMesh(env_meshes[m], data, {3, 3, 2}, idx);
      // Faceted: each triangle's three normals equal and perpendicular to it (a supplied normal tilted from
      // its face would make the per-vertex two-sided flip differ from the per-fragment one).
      env_faceted.push_back(std::all_of(mesh.triangles.begin(), mesh.triangles.end(), [&](const auto& t) {
        const glm::vec3 n = mesh.normals[t.x];
        const Vec3 face = glm::cross(Vec3(mesh.positions[t.y] - mesh.positions[t.x]), Vec3(mesh.positions[t.z] - mesh.positions[t.x]));
        const double len = glm::length(face);
        const bool perpendicular = len == 0 || std::abs(glm::dot(face / len, Vec3(n))) >= 1 - 1e-6;
        return perpendicular && glm::length(mesh.normals[t.y] - n) <= 1e-6f && glm::length(mesh.normals[t.z] - n) <= 1e-6f;
      }));
      Vec3 lo(mesh.positions.empty() ? glm::vec3(0) : mesh.positions[0]), hi(lo);
      for (const glm::vec3& p : mesh.positions) {
        lo = glm::min(lo, Vec3(p));
        hi = glm::max(hi, Vec3(p));
      }
      env_bounds.push_back({lo, hi});
      env_textured.push_back(scene.materials[size_t(mesh.material)].texture >= 0);
      // Its program, built now (not in the first frame's first pass) so that its compile time and any
      // compile error come with the renderer.
      envProgram(env_faceted.back(), env_textured.back(), false);
    }
    checkGlError("uploading the environment");
  }

  ~Impl() {
    for (LensMaps& m : lens_maps)
      for (GLuint t : {m.front, m.back, m.mask})
        if (t) glDeleteTextures(1, &t);
    for (MirrorMaps& m : mirror_maps)
      for (GLuint t : m.textures)
        if (t) glDeleteTextures(1, &t);
    for (auto& m : env_meshes) m.release();
    for (auto& m : element_meshes) m.release();
    if (empty_vao) glDeleteVertexArrays(1, &empty_vao);
    if (mask_vbo) glDeleteBuffers(1, &mask_vbo);
    if (mask_vao) glDeleteVertexArrays(1, &mask_vao);
  }

  // The uniforms of shaders/shading.glsl, for a pass whose camera origin is `origin`.
  void setLights(const Program& p, const Vec3& origin) const {
    Vec3 ambient(0.0);
    std::vector<float> dir_vec, dir_rad, point_pos, point_rad;
    auto push = [](std::vector<float>& to, const Vec3& v) { to.insert(to.end(), {float(v.x), float(v.y), float(v.z)}); };
    for (const Light& l : scene.lights) {
      switch (l.type) {
        case Light::Type::Ambient: ambient += l.radiance; break;
        case Light::Type::Directional: push(dir_vec, l.direction), push(dir_rad, l.radiance); break;
        case Light::Type::Point: push(point_pos, l.position - origin), push(point_rad, l.radiance); break;
      }
    }
    p.set("u_ambient", glm::vec3(ambient));
    if (!dir_vec.empty()) {
      p.setVec3("u_dir_light_dir", dir_vec.data(), int(dir_vec.size() / 3));
      p.setVec3("u_dir_light_radiance", dir_rad.data(), int(dir_rad.size() / 3));
    }
    if (!point_pos.empty()) {
      p.setVec3("u_point_light_pos", point_pos.data(), int(point_pos.size() / 3));
      p.setVec3("u_point_light_radiance", point_rad.data(), int(point_rad.size() / 3));
    }
  }

  // The environment meshes' bounding boxes relative to `origin`.
  std::vector<std::array<Vec3, 2>> environmentBoxes(const Vec3& origin) const {
    std::vector<std::array<Vec3, 2>> boxes(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const Vec3 to_anchor = scene.meshes[m].anchor - origin;
      boxes[m] = {env_bounds[m][0] + to_anchor, env_bounds[m][1] + to_anchor};
    }
    return boxes;
  }

  // The order to draw them in: the scene's, or sorted by their distance (RendererOptions::sort_environment).
  std::vector<size_t> environmentDrawOrder(const std::vector<std::array<Vec3, 2>>& boxes, bool reversed_depth) const {
    if (options.sort_environment) return depthSortedDrawOrder(boxes, reversed_depth);
    std::vector<size_t> order(boxes.size());
    for (size_t m = 0; m < order.size(); ++m) order[m] = m;
    return order;
  }

  // Sky and environment from a camera at `origin`; `view_origin` is where the viewing rays start (for the
  // two-sided normal), relative to `origin`.
  // reversed_depth: the zooming-region pass (view_volume.h): the fragment farthest from the camera wins.
  // rays_from: where the viewing rays start (two-sided normals face it); the camera unless given.
  // Forward passes (not reversed_depth) draw the sky last, where the depth buffer is still clear, so that
  // no pixel is shaded twice for it; what was drawn into the target before (the elements of the second
  // pass, drawn first so that the environment behind them fails the early depth test) stays.
  // Returns how many closed convex meshes it drew and culled.
  // with_seen: write seen points even when RendererOptions::seen_points is off (impostor cube maps).
  CullCount drawEnvironment(const Mat4& view, const Mat4& proj, const Vec3& origin, bool reversed_depth = false,
                            const Vec3* rays_from = nullptr, bool planes = false, bool with_seen = false,
                            bool peel = false) const {
    const Mat4 vp = relativeViewProj(proj, view, origin);
    const Program& sky = skyProgram(planes, with_seen, peel);
    auto drawSky = [&] {
      sky.use();
      if (peel) {
        sky.set("u_peel", kPeelUnit);
        sky.set("u_first_colour", kFirstCubeUnit);
        sky.set("u_first_normal", kFirstCubeUnit + 1);
      }
      sky.set("u_inv_view_proj", toFloat(glm::inverse(vp)));
      sky.set("u_background", glm::vec3(scene.render.background));
      sky.set("u_far", float(scene.render.far_distance_m));
      glBindVertexArray(empty_vao);
      glDrawArrays(GL_TRIANGLES, 0, 3);
    };
    if (reversed_depth) {  // depth cleared to 0: the sky first, without depth
      glDisable(GL_DEPTH_TEST);
      glDepthMask(GL_FALSE);
      drawSky();
    }
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(reversed_depth ? GL_GREATER : GL_LESS);
    // The programs of the kinds of mesh the scene has, [faceted][textured], set up for this pass.
    const Program* programs[2][2] = {};
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const bool faceted = env_faceted[m], textured = env_textured[m];
      const Program*& p = programs[faceted][textured];
      if (p) continue;
      p = &envProgram(faceted, textured, planes, with_seen, peel);
      p->use();
      if (peel) p->set("u_peel", kPeelUnit);
      p->set("u_view_proj", toFloat(vp));
      p->set("u_view_origin", rays_from ? glm::vec3(*rays_from - origin) : glm::vec3(0.0f));
      if (textured) p->set("u_texture", 0);
      setLights(*p, origin);
    }
    glActiveTexture(GL_TEXTURE0);
    // Back faces of closed convex meshes that near clipping cannot cut open (RendererOptions::cull_back_faces,
    // NearClip): a ray from the centre of projection to a back-face point first crosses a front face
    // of the same solid, itself beyond the near plane, which the depth test keeps instead. Not with reversed
    // depth, where the farther face wins.
    const bool may_cull = options.cull_back_faces && !reversed_depth;
    const NearClip near_clip(vp);
    glDisable(GL_CULL_FACE);  // whatever an interrupted pass left
    if (may_cull) {
      glCullFace(GL_BACK);
      glFrontFace(facingTrianglesWindCounterClockwise(vp) ? GL_CCW : GL_CW);
    }
    bool culling = false;
    CullCount count;
    const std::vector<std::array<Vec3, 2>> boxes = environmentBoxes(origin);  // camera-relative
    for (const size_t m : environmentDrawOrder(boxes, reversed_depth)) {
      const EnvMesh& mesh = scene.meshes[m];
      const DiffuseMaterial& mat = scene.materials[size_t(mesh.material)];
      const Program& p = *programs[env_faceted[m]][env_textured[m]];
      const bool cull = may_cull && mesh.closed_convex && near_clip.cannotOpen(boxes[m][0], boxes[m][1]);
      count.drawn += mesh.closed_convex;
      count.culled += cull;
      if (cull != culling) {
        cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
        culling = cull;
      }
      p.use();
      p.set("u_offset", glm::vec3(mesh.anchor - origin));
      p.set("u_albedo", glm::vec3(mat.color));
      if (env_textured[m]) glBindTexture(GL_TEXTURE_2D, textures[size_t(mat.texture)].name());
      draw(env_meshes[m]);
    }
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
    if (!reversed_depth) {  // the sky triangle lies at depth 1: it passes only where nothing was drawn
      glDepthFunc(GL_LEQUAL);
      glDepthMask(GL_FALSE);
      drawSky();
      glDepthMask(GL_TRUE);
      glDepthFunc(GL_LESS);
    }
    return count;
  }

  // Lens e's height maps (RGBA32F: z and the outward normal) and outline mask (R32F), rebuilt when missing or
  // built from other surfaces or another outline; returns 1 when built.
  int updateLensMaps(size_t e) {
    if (lens_maps.size() < scene.elements.size()) lens_maps.resize(scene.elements.size());
    LensMaps& m = lens_maps[e];
    const Element& el = scene.elements[e];
    if (m.front && m.front_surface == el.lens.front && m.back_surface == el.lens.back && m.outline == el.lens.outline)
      return 0;
    m.map = buildLensHeightMap(el, options.lens_height_map_size);
    m.front_surface = el.lens.front;
    m.back_surface = el.lens.back;
    m.outline = el.lens.outline;
    uploadDataTexture(m.front, GL_RGBA32F, m.map.nx, m.map.ny, 4, m.map.front.data());
    uploadDataTexture(m.back, GL_RGBA32F, m.map.nx, m.map.ny, 4, m.map.back.data());
    uploadDataTexture(m.mask, GL_R32F, m.map.nx, m.map.ny, 1, m.map.inside.data());
    checkGlError("uploading a lens's refractor height maps");
    return 1;
  }
  // Mirror e's surface maps, rebuilt when missing or built from another surface or outline; returns 1 when
  // built.
  int updateMirrorMaps(size_t e) {
    if (mirror_maps.size() < scene.elements.size()) mirror_maps.resize(scene.elements.size());
    MirrorMaps& m = mirror_maps[e];
    const Element& el = scene.elements[e];
    if (m.textures[0] && m.surface == el.surface && m.has_outline == el.has_outline &&
        (!el.has_outline || m.outline == el.outline))
      return 0;
    m.map = buildSurfaceMap(*el.surface, options.surface_map_size, el.has_outline ? &el.outline : nullptr);
    m.surface = el.surface;
    m.has_outline = el.has_outline;
    m.outline = el.outline;
    // The derivatives only steer the shader's Gauss-Newton steps: half floats do.
    const std::vector<float>* data[4] = {&m.map.position, &m.map.du, &m.map.dv, &m.map.normal};
    const GLint formats[4] = {GL_RGBA32F, GL_RGBA16F, GL_RGBA16F, GL_RGBA32F};
    for (size_t k = 0; k < 4; ++k) uploadDataTexture(m.textures[k], formats[k], m.map.n, m.map.n, 4, data[k]->data());
    checkGlError("uploading a mirror's surface maps");
    for (auto* a : {&m.map.position, &m.map.du, &m.map.dv, &m.map.normal}) std::vector<float>().swap(*a);
    return 1;
  }
  // The uniforms of a mirror's impostor draw: its surface maps on units 2 to 5, the samples' placement in
  // their textures, and its pose.
  void setMirrorMaps(const Program& p, size_t e) {
    const MirrorMaps& m = mirror_maps.at(e);
    bindDataTextures(p, 2, {{"u_surf_p", m.textures[0]}, {"u_surf_du", m.textures[1]}, {"u_surf_dv", m.textures[2]},
                            {"u_surf_n", m.textures[3]}});
    const double n = m.map.n;
    p.set("u_sm", glm::vec2(float((n - 1) / n), float(0.5 / n)));
    p.set("u_to_local", glm::mat3(Mat3(scene.elements[e].world_to_local)));
  }

  // The uniforms of a lens's impostor draw (shaders/element.frag, MODE_IMPOSTOR with LENS): its height maps
  // and outline mask on units 2 to 4, their placement, its pose, its index at the R, G and B wavelengths, and
  // the tracer's depth limit and far distance.
  // first_unit and rotation: where a mirror's program that meets the lens in its cubes takes them
  // (LENS_IN_CUBES: after the cubes, u_lens_to_local).
  void setLensMaps(const Program& p, size_t e, int first_unit = 2, const char* rotation = "u_to_local") {
    const LensMaps& m = lens_maps.at(e);
    const Element& el = scene.elements[e];
    bindDataTextures(p, first_unit, {{"u_lens_front", m.front}, {"u_lens_back", m.back}, {"u_lens_mask", m.mask}});
    p.set("u_hm_reach", float(m.map.reach));
    p.set("u_max_events", scene.render.max_depth - 1);
    p.set("u_far", float(scene.render.far_distance_m));
    p.set("u_hm", glm::vec4(float(m.map.x0), float(m.map.y0), float(1.0 / (m.map.nx * m.map.dx)),
                            float(1.0 / (m.map.ny * m.map.dy))));
    p.set("u_hm_z", glm::vec2(float(m.map.back_z_min), float(m.map.front_z_max)));
    p.set(rotation, glm::mat3(Mat3(el.world_to_local)));
    const double* wl = kRgbWavelengths_nm;
    p.set("u_index", glm::vec3(float(el.dispersion.index(wl[0])), float(el.dispersion.index(wl[1])),
                               float(el.dispersion.index(wl[2]))));
  }

  // Impostor mode with several elements (seeds 000's distance-normal impostors): each element's cubes also show
  // the other mirrors, with their surface points and normals, and a search that meets one goes on in that
  // mirror's cubes; and the scene's lens, if it has one only (lensInCubes), through which the search refracts
  // with the lens's height maps. The number of elements the fragment loop switches between (CUBE_ELEMENTS), or
  // 0: one element, no mirror to meet, or more elements than kMaxCubeElements or the texture units allow (then
  // each cube shows the environment only).
  static constexpr int kMaxCubeElements = 4;
  static constexpr int kFirstCubeUnit = 6;  // after a cube pair (0, 1) and the element's own maps (2 to 5)
  static constexpr int kPeelUnit = 1;       // the first layer's seen points while its second layer is drawn
  size_t lensCount() const {
    return size_t(std::count_if(scene.elements.begin(), scene.elements.end(),
                                [](const Element& e) { return e.type == ElementType::Lens; }));
  }
  int cubeElements(RenderMode mode) const {
    const int n = int(scene.elements.size());
    const bool mirror = lensCount() < size_t(n);
    // Three cubes per element, and the lens's three height maps for the mirrors that meet it.
    if (mode != RenderMode::Impostor || n < 2 || !mirror || n > kMaxCubeElements ||
        kFirstCubeUnit + 3 * n + (lensCount() == 1 ? 3 : 0) > max_texture_units)
      return 0;
    return n;
  }
  // The layers of each impostor distance map (render.impostor_layers; seeds 001): 2 where the texture units allow
  // the second layer's cubes (two more for one element, three more an element with CUBE_ELEMENTS), else 1.
  int impostorLayers(RenderMode mode) const {
    if (mode != RenderMode::Impostor || scene.render.impostor_layers < 2) return 1;
    const int follow = cubeElements(mode);
    const int units = follow > 0 ? kFirstCubeUnit + 6 * follow + (lensCount() == 1 ? 3 : 0) : kFirstCubeUnit + 2;
    return units <= max_texture_units ? 2 : 1;
  }
  // Whether the lens is drawn in the other elements' cubes: the scene has one (the mirrors' programs take its
  // maps; its own program, which meets it again through a mirror, has them already).
  bool lensInCubes(RenderMode mode) const { return cubeElements(mode) > 0 && lensCount() == 1; }
  // The colour channels of element e's impostor program (IMPOSTOR_CHANNELS): a lens with dispersion refracts R,
  // G and B with their own indices, and so does a mirror that can show such a lens in its cubes.
  int impostorChannels(size_t e) const {
    auto dispersive = [&](size_t k) { return dispersionChannels(scene, int(k)).size() > 1; };
    if (scene.elements[e].type == ElementType::Lens) return dispersive(e) ? 3 : 1;
    if (!lensInCubes(RenderMode::Impostor)) return 1;
    for (size_t k = 0; k < scene.elements.size(); ++k)
      if (scene.elements[k].type == ElementType::Lens && dispersive(k)) return 3;
    return 1;
  }
  // The uniforms of the fragment loop over every element's cubes (CUBE_ELEMENTS), for element e drawn from a
  // camera at `origin`: three cubes per element on units from kFirstCubeUnit (and, with two layers, the second
  // layer's three after them), their origins, the mirrors' materials, and the tracer's depth limit.
  void setCubeElements(const Program& p, size_t e, const Vec3& origin, int layers) {
    const int n = int(scene.elements.size());
    for (size_t k = 0; k < scene.elements.size(); ++k) {
      const Element& el = scene.elements[k];
      const std::string i = "[" + std::to_string(k) + "]";
      const char* names[2][3] = {{"u_cubes", "u_seen_cubes", "u_normal_cubes"},
                                 {"u_cubes1", "u_seen_cubes1", "u_normal_cubes1"}};
      for (int layer = 0; layer < layers; ++layer)
        for (int a = 0; a < 3; ++a) {
          const int unit = kFirstCubeUnit + 3 * (layer * n + int(k)) + a;
          glActiveTexture(GLenum(GL_TEXTURE0 + unit));
          glBindTexture(GL_TEXTURE_CUBE_MAP, (layer ? cubes1 : cubes)[k]->colors[size_t(a)]);
          p.set(names[layer][a] + i, unit);
        }
      p.set("u_cube_centre" + i, glm::vec3(Vec3(el.local_to_world[3]) - origin));
      p.set("u_el_metal" + i, el.mirror.metal ? 1 : 0);
      p.set("u_el_reflectance" + i, glm::vec3(el.mirror.reflectance));
      p.set("u_el_metal_n" + i, glm::vec3(el.mirror.n));
      p.set("u_el_metal_k" + i, glm::vec3(el.mirror.k));
    }
    glActiveTexture(GL_TEXTURE0);
    p.set("u_self", int(e));
    p.set("u_max_depth", scene.render.max_depth);
    // The scene's lens, which the search can meet: a mirror's program takes its maps after the cubes; the
    // lens's own has them (setLensMaps) and needs its rotation under the loop's name too.
    if (lensInCubes(RenderMode::Impostor))
      for (size_t k = 0; k < scene.elements.size(); ++k) {
        if (scene.elements[k].type != ElementType::Lens) continue;
        if (k == e) p.set("u_lens_to_local", glm::mat3(Mat3(scene.elements[k].world_to_local)));
        else setLensMaps(p, k, kFirstCubeUnit + 3 * layers * n, "u_lens_to_local");
        p.set("u_cube_lens", int(k));
      }
  }

  // Element m drawn into a face of another element's impostor cubes, from a camera at `origin` (view_proj
  // relative to it), before the environment (CUBE_GEOMETRY): a mirror's exact surface point and normal per
  // fragment, a lens's mesh.
  void drawCubeElement(size_t m, const Mat4& view_proj, const Vec3& origin, const MeshBuffers& mesh, bool peel) {
    const Element& el = scene.elements[m];
    const Vec3 anchor = Vec3(el.local_to_world[3]);
    const bool lens = el.type == ElementType::Lens;
    const Program& p = cubeGeometryProgram(lens, peel);
    p.use();
    if (peel) p.set("u_peel", kPeelUnit);
    p.set("u_view_proj", toFloat(view_proj));
    p.set("u_offset", glm::vec3(anchor - origin));
    p.set("u_view_origin", glm::vec3(0.0f));
    p.set("u_seen_offset", glm::vec3(anchor - origin));
    setElementMaterial(p, el, int(m));
    if (!lens) setMirrorMaps(p, m);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    draw(mesh);
  }

  void setElementMaterial(const Program& p, const Element& el, int index) const {
    p.set("u_element_id", float(index + 1));
    p.set("u_metal", el.mirror.metal ? 1 : 0);
    p.set("u_reflectance", glm::vec3(el.mirror.reflectance));
    p.set("u_metal_n", glm::vec3(el.mirror.n));
    p.set("u_metal_k", glm::vec3(el.mirror.k));
  }

  // Whole-element mesh (plain, envmap and impostor modes, and elements drawn dark at the depth limit):
  // position relative to the element's origin, normal; for an envmap lens the exact exit direction of each
  // vertex's ray in a_st0 and its Fresnel transmittance in a_w0 (the "refraction vectors" baseline); the
  // vertex's surface parameters (u, v), normalised to the surface's domain, in a_st1 (the impostor mirror's
  // start on its surface maps).
  void uploadElementGrid(MeshBuffers& mb, const ElementFrame& f, const Vec3& anchor) {
    std::vector<float> data;
    data.reserve(f.world_pos.size() * kElementFloats);
    const bool has_rays = !f.rays.empty();
    const cad::ParamDomain domain = scene.elements[size_t(f.element)].frontSurface().domain();
    for (size_t i = 0; i < f.world_pos.size(); ++i) {
      glm::vec3 p(f.world_pos[i] - anchor), n(f.world_normal[i]);
      const glm::vec3 d = has_rays ? glm::vec3(f.rays[0][i].dir) : glm::vec3(0, 0, 1);
      const glm::vec3 tr = has_rays ? glm::vec3(f.rays[0][i].transmittance) : glm::vec3(1);
      // The surface parameters normalised to the domain in double (pvrr/impostor/surface_map.h).
      const glm::vec2 uv = i < f.grid.params.size()
                               ? glm::vec2((f.grid.params[i].x - domain.u0) / (domain.u1 - domain.u0),
                                           (f.grid.params[i].y - domain.v0) / (domain.v1 - domain.v0))
                               : glm::vec2(0.5f);
      data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, d.x, d.y, d.z, uv.x, uv.y, 1, 0, 0, 1, tr.x, tr.y, tr.z,
                               0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0});
    }
    std::vector<uint32_t> idx;
    for (const auto& t : f.grid.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
    uploadMesh(mb, data, kElementLayout, idx);
  }

  // One patch of a PVRR element for one set of (up to) three channels, `set` = 0, 1, ...: the projective
  // texture coordinates of channels 3 set + j, their weights (colour weight * transmittance, 0 for the
  // padding of the last set), and the coordinates of channel `seen_channel` for the seen point.
  void uploadPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor, size_t set,
                   size_t seen_channel) {
    const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
    const size_t channels = pv.st.size();
    std::vector<float> data;
    data.reserve(gp.vertices.size() * kElementFloats);
    Vec3 weight[3];
    for (size_t j = 0; j < 3; ++j)
      weight[j] = 3 * set + j < channels ? channelWeight(f.channels, 3 * set + j) : Vec3(0.0);
    for (size_t k = 0; k < gp.vertices.size(); ++k) {
      const uint32_t vi = gp.vertices[k];
      glm::vec3 p(f.world_pos[vi] - anchor), n(f.world_normal[vi]);
      data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
      const double q = pv.q[k];
      for (size_t j = 0; j < 3; ++j) {
        const Vec2 st = pv.st[std::min(3 * set + j, channels - 1)][k];
        data.insert(data.end(), {float(st.x * q), float(st.y * q), float(q)});
      }
      for (size_t j = 0; j < 3; ++j) {
        const Vec3 w = weight[j] * f.rays[std::min(3 * set + j, channels - 1)][vi].transmittance;
        data.insert(data.end(), {float(w.x), float(w.y), float(w.z)});
      }
      const Vec2 st = pv.st[seen_channel][k];
      data.insert(data.end(), {float(st.x * q), float(st.y * q), float(q)});
      // Totally reflected channels: their map weight is 0 and the tracer's colour takes its place, added in
      // the draw of their set; the seen point follows the seen channel (first draw).
      Vec3 traced(0.0);
      for (size_t j = 0; j < 3 && 3 * set + j < channels; ++j) {
        const VertexRay& r = f.rays[3 * set + j][vi];
        if (r.traced) traced += weight[j] * r.traced_color;
      }
      const VertexRay& seen_ray = f.rays[seen_channel][vi];
      const bool seen_traced = set == 0 && seen_ray.traced;
      const glm::vec3 ts = seen_traced ? glm::vec3(seen_ray.traced_seen - anchor) : glm::vec3(0.0f);
      data.insert(data.end(), {float(traced.x), float(traced.y), float(traced.z), seen_traced ? 1.0f : 0.0f, ts.x, ts.y, ts.z});
    }
    std::vector<uint32_t> idx;
    for (const auto& t : gp.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
    uploadMesh(mb, data, kElementLayout, idx);
  }

  // The map texture of slot i: size x size, colour RGBA32F (planes: three R32F planes), then the seen points
  // (RGBA32F) when they are wanted.
  Framebuffer& mapTarget(size_t i, int size, bool planes) {
    if (maps.size() <= i) maps.resize(i + 1);
    const bool is_planes = maps[i] && maps[i]->colorFormat(0) == ColorFormat::R32F;
    if (!maps[i] || maps[i]->width() != size || is_planes != planes) {
      // RGBA32F colour: llvmpipe filters it faster than RGBA16F (three bilinear reads of a 1024^2 map over
      // 1280 x 720: 14.9 against 18.2 ms), and it keeps values above 1 exactly. Planes: one float a read.
      std::vector<ColorFormat> formats = planes ? std::vector<ColorFormat>{ColorFormat::R32F, ColorFormat::R32F, ColorFormat::R32F}
                                                : std::vector<ColorFormat>{ColorFormat::RGBA32F};
      if (options.seen_points) formats.push_back(ColorFormat::RGBA32F);
      maps[i] = std::make_unique<Framebuffer>(size, size, formats, DepthFormat::Depth32F);
      // Defined contents once: a pass renders only the lower-left region of the texture and may leave texels
      // unshaded (closeUnreadTexels); a fetch clamped to the region's far edge (u_st_max) may still weigh the
      // texel past it by a rounding residue, which must not meet a NaN.
      maps[i]->clear({0.0f, 0.0f, 0.0f, 0.0f});
      // Colour and seen points filter linearly: seen points are exact within a surface and blend only across
      // depth edges (nearest filtering would quantise every seen point by up to half a texel).
      for (int a = 0; a < maps[i]->colorCount(); ++a) {
        glBindTexture(GL_TEXTURE_2D, maps[i]->colorTexture(a));
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      }
    }
    return *maps[i];
  }

  // --- multiple reflection (recursive PVRR with an explicit work list) ---

  // An element drawn inside a first pass besides the environment: with its own PVRR maps (its vertex rays
  // start from that pass's viewpoint), or dark where the tracer reaches its depth limit.
  struct NestedDraw {
    int element = -1;
    const ElementFrame* frame = nullptr;  // null: drawn dark
    size_t first_slot = 0;                // map slot of frame->views[0]; views[v] uses first_slot + v
  };
  // One first pass: the map of one patch view.
  struct MapPass {
    const ElementFrame* owner = nullptr;
    size_t view = 0;
    int depth = 0;     // the tracer's depth (events before) of what this map shows: 1 behind a mirror seen
                       // from the eye, 2 behind a lens (two interfaces)
    size_t slot = 0;   // index into `maps`
    int size = 0;      // the map texture's width and height (nestedMapSize for nested maps)
    int side = 0;      // the longer side rendered (topLevelMapSide; nested: half the parent's): the pass renders the
                       // lower-left mapTexels(volume, side) of the texture
    bool visible = true;  // false: a top-level element the observer cannot see; its map is left as it is
    std::vector<NestedDraw> nested;
  };
  std::vector<MapPass> passes;                            // this frame's first passes, parents before children
  std::vector<std::unique_ptr<ElementFrame>> nested_frames;  // elements as seen from virtual viewpoints
  size_t next_mesh = 0;

  static int interfaces(const Element& el) { return el.type == ElementType::Lens ? 2 : 1; }
  // Planned first passes that render a map (the budget counts these).
  size_t visiblePasses() const {
    return size_t(std::count_if(passes.begin(), passes.end(), [](const MapPass& m) { return m.visible; }));
  }
  // Whether cached rays were traced for these channels (wavelengths and weights, not just their count).
  static bool sameChannels(const std::vector<ChannelSpec>& a, const std::vector<ChannelSpec>& b) {
    if (a.size() != b.size()) return false;
    for (size_t c = 0; c < a.size(); ++c)
      if (a[c].wavelength_nm != b[c].wavelength_nm || channelWeight(a, c) != channelWeight(b, c)) return false;
    return true;
  }
  // A top-level element whose interfaces reach render.max_depth (a lens with max_depth 1): the tracer
  // absorbs at its back surface, so it is drawn dark and needs no map.
  bool beyondDepth(const ElementFrame& f) const {
    return interfaces(scene.elements[size_t(f.element)]) > scene.render.max_depth;
  }

  VertexStageOptions optionsFor(size_t e) const {
    VertexStageOptions o = options.vertex;
    if (o.channels.empty()) o.channels = dispersionChannels(scene, int(e));
    // As seen from the eye: the tracer's whole budget (none for a lens drawn dark at the depth limit).
    o.tir_trace_depth = interfaces(scene.elements[e]) > scene.render.max_depth ? 0 : scene.render.max_depth;
    return o;
  }

  // Whether the top-level patch view v of f needs its map: the observer sees the patch and the element is
  // not dark at the depth limit.
  bool topLevelVisible(const ElementFrame& f, size_t v) const {
    const Observer& ob = scene.observer;
    return f.views[v].in_view && mayBeInVolume(f.world_pos, ob.visibilityProjection() * ob.view()) && !beyondDepth(f);
  }

  // Map reuse (RendererOptions::map_reuse_margin_deg). Whether the top-level maps of the last first pass
  // (cache.maps) serve this frame's views: the same slots; every view the observer sees was rendered, lies
  // inside its map's frustum (frustumContains), needs at most 15 % more texel density than the map has
  // (and at least half), its viewpoint moved by under a quarter of the map's smallest texel angle as seen
  // from its nearest hit point (parallax), and no other element reaches into the map's volume (nothing to
  // nest; an element is never drawn in its own maps). If so each seen view takes its map's volume and its
  // texture coordinates are projected through it; `note` says by what margin. Otherwise `note` says why not.
  bool reuseMaps(std::vector<ElementFrame>& frames, const FrameCache& cache, std::string* note) const {
    size_t slots = 0;
    for (const ElementFrame& f : frames) slots += f.views.size();
    if (cache.maps.empty() || cache.maps_serial != first_pass_serial) {
      *note = cache.maps_serial != first_pass_serial && !cache.maps.empty()
                  ? "this renderer drew other maps since"
                  : "no reusable maps (the last first pass was not widened: a first frame, or nested passes)";
      return false;
    }
    if (cache.maps.size() != slots) {
      *note = "the patches changed";
      return false;
    }
    double worst_parallax = 0, worst_move = 0;
    std::vector<char> visible(slots, 0);  // per slot: the observer sees it (the views to check and to move)
    size_t slot = 0;
    for (const ElementFrame& f : frames)
      for (size_t v = 0; v < f.views.size(); ++v, ++slot) {
        const FrameCache::Map& m = cache.maps[slot];
        if (m.element != f.element || m.view != v) {
          *note = "the patches changed";
          return false;
        }
        visible[slot] = topLevelVisible(f, v);
        if (!visible[slot]) continue;
        const PatchView& pv = f.views[v];
        const ViewVolume &W = m.volume, &V = pv.volume;
        if (!m.rendered || V.backward || W.backward) {
          *note = !m.rendered ? "a patch came into view" : "a reversed (zooming) map is not reused";
          return false;
        }
        const bool planes = slot < maps.size() && maps[slot] && maps[slot]->colorFormat(0) == ColorFormat::R32F;
        if (planes != rgbLens(scene.elements[size_t(f.element)], f)) {
          *note = "the colour channels changed";
          return false;
        }
        if (!frustumContains(W, V)) {
          *note = "a view left its map's margin";
          return false;
        }
        const double need = topLevelMapSide(scene, f, pv, options) / longerExtentTan(V),
                     have = m.side / longerExtentTan(W);
        if (have < need / 1.15 || have > 2 * need) {
          *note = "the texel density needed changed";
          return false;
        }
        double nearest = kInf;
        const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
        for (const auto& channel : f.rays)
          for (uint32_t vi : gp.vertices)
            if ((f.in_view.empty() || f.in_view[vi]) && channel[vi].status == VertexStatus::Hit)
              nearest = std::min(nearest, glm::length(channel[vi].hit - V.eye));
        if (!std::isfinite(nearest)) {  // every ray escaped or was flagged: nothing bounds the parallax
          *note = "no hit point bounds the parallax";
          return false;
        }
        const double move = glm::length(V.eye - W.eye), parallax = move / nearest / minTexelAngle(W, m.side);
        if (!(parallax <= 0.25)) {
          *note = "the viewpoint moved too far (parallax " + fmt("%.2g", parallax) + " texel)";
          return false;
        }
        const Mat4 map_clip = W.projection * W.view;
        for (const ElementFrame& b : frames)
          if (b.element != f.element && mayBeInVolume(b.world_pos, map_clip)) {
            *note = "an element reaches into a map's volume";
            return false;
          }
        worst_parallax = std::max(worst_parallax, parallax);
        worst_move = std::max(worst_move, move);
      }
    slot = 0;
    for (ElementFrame& f : frames)
      for (size_t v = 0; v < f.views.size(); ++v, ++slot)
        if (visible[slot]) {
          f.views[v].volume = cache.maps[slot].volume;
          projectPatchMap(f, f.views[v]);
        }
    *note = "map reuse: every view lies inside the maps drawn " + std::to_string(cache.maps_age + 1) +
            " frame(s) ago with margins of up to " + fmt("%.3g", options.map_reuse_margin_deg) + " deg; viewpoints moved <= " +
            fmt("%.3g", 1e3 * worst_move) + " mm (parallax <= " + fmt("%.3g", worst_parallax) + " texel)";
    return true;
  }

  // Widens every top-level forward view by the reuse margin (widenViewVolume) at the texel density it needs
  // (its side scaled by the wider extent) in a texture 25 % larger than patchMapSize, and projects its
  // texture coordinates through the wider volume. A narrow view gets a smaller margin, so that its longer
  // extent grows by at most kMaxWidening and its density is kept within that texture. Returns each slot's
  // texture size and side.
  static constexpr double kMaxWidening = 1.2;
  std::vector<std::array<int, 2>> widenMaps(std::vector<ElementFrame>& frames) const {
    std::vector<std::array<int, 2>> out;
    for (ElementFrame& f : frames)
      for (PatchView& pv : f.views) {
        const int base = patchMapSize(options.map_size, std::max<size_t>(1, inView(f)));
        const int size = std::min(32 * int(std::ceil(1.25 * base / 32.0)), std::max(base, max_texture_size)),
                  side = topLevelMapSide(scene, f, pv, options);
        if (pv.volume.backward) {
          out.push_back({size, side});
          continue;
        }
        const ViewVolume narrow = pv.volume;
        double margin = radians(options.map_reuse_margin_deg);
        pv.volume = widenViewVolume(narrow, margin);
        double wider = longerExtentTan(pv.volume) / longerExtentTan(narrow);
        for (int i = 0; i < 8 && wider > kMaxWidening; ++i) {  // the extent grows about linearly with the margin
          margin *= 0.98 * (kMaxWidening - 1) / (wider - 1);
          pv.volume = widenViewVolume(narrow, margin);
          wider = longerExtentTan(pv.volume) / longerExtentTan(narrow);
        }
        out.push_back({size, std::min(size, 32 * int(std::ceil(side * wider / 32.0)))});
        projectPatchMap(f, pv);
      }
    return out;
  }

  MeshBuffers& meshSlot() {
    if (element_meshes.size() <= next_mesh) element_meshes.resize(next_mesh + 1);
    return element_meshes[next_mesh++];
  }

  // Where the light that reaches each of `points` through the owner's patch leaves the owner (beyond the
  // paper, which starts the nested rays at the outer virtual viewpoint and so inherits its fit residual):
  // the outgoing-ray origins of the owner's vertices (mirror points, lens back points), interpolated at the
  // point's position in the patch's map with the barycentric coordinates, in texture space, of the owner
  // triangle that holds it there. A point outside the patch's image extrapolates from the nearest
  // triangle, up to half a triangle; beyond that (or behind the map camera) it uses the viewpoint itself.
  static std::vector<Vec3> rayOrigins(const ElementFrame& owner, const PatchView& pv, const std::vector<Vec3>& points) {
    const cad::GridPatch& gp = owner.grid_patches[size_t(pv.patch)];
    const size_t fc = owner.rays.size() / 2;
    const std::vector<Vec2>& st = pv.st[fc];
    std::vector<Vec3> out(points.size(), pv.volume.eye);
    // A vertex out of the viewer's view or with a flagged ray (TIR, edge band) has placeholder texture
    // coordinates: its triangles say nothing about where the map shows a point.
    const auto usable = [&](uint32_t k) {
      const uint32_t vi = gp.vertices[k];
      return (owner.in_view.empty() || owner.in_view[vi]) && owner.rays[fc][vi].status != VertexStatus::Tir;
    };
    for (size_t i = 0; i < points.size(); ++i) {
      const Vec2 p = projectToTexture(pv.volume, points[i]);
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      double best = -kInf, l[3] = {0, 0, 0};
      const cad::Triangle* best_tri = nullptr;
      for (const cad::Triangle& t : gp.triangles) {
        if (!usable(t.x) || !usable(t.y) || !usable(t.z)) continue;
        const Vec2 a = st[t.x], e1 = st[t.y] - a, e2 = st[t.z] - a, r = p - a;
        const double den = e1.x * e2.y - e2.x * e1.y;
        if (!(std::abs(den) > 0)) continue;
        const double l1 = (r.x * e2.y - e2.x * r.y) / den, l2 = (e1.x * r.y - r.x * e1.y) / den, l0 = 1 - l1 - l2;
        const double m = std::min(l0, std::min(l1, l2));
        if (m > best) {
          best = m;
          l[0] = l0;
          l[1] = l1;
          l[2] = l2;
          best_tri = &t;
          if (m >= 0) break;
        }
      }
      if (!best_tri || best < -0.5) continue;
      const auto origin = [&](uint32_t k) { return owner.rays[fc][gp.vertices[k]].origin; };
      out[i] = l[0] * origin(best_tri->x) + l[1] * origin(best_tri->y) + l[2] * origin(best_tri->z);
    }
    return out;
  }

  // Plans this frame's first passes: the top-level patch views of `frames` (slots 0..), then, breadth
  // first, for every pass the other elements inside its view volume, each traced and fitted from the pass's
  // viewpoint with its own maps appended to the list, down to the scene's depth limit. Children always
  // follow their parent, so rendering the list backwards renders every map before the pass that reads it.
  // Returns the number of nested passes; `dark` counts elements drawn dark at the depth limit or budget.
  // `top_size_side`: the texture size and rendered side of each top-level slot (widened maps); default
  // patchMapSize and topLevelMapSide.
  size_t planPasses(const std::vector<ElementFrame>& frames, const std::vector<VertexStageOptions>& opts,
                    size_t* dark, bool* budget_hit, const std::vector<std::array<int, 2>>* top_size_side = nullptr) {
    passes.clear();
    nested_frames.clear();
    *dark = 0;
    *budget_hit = false;
    size_t slot = 0;
    for (const ElementFrame& f : frames)
      for (size_t v = 0; v < f.views.size(); ++v) {
        const bool given = top_size_side && slot < top_size_side->size();
        passes.push_back({&f, v, interfaces(scene.elements[size_t(f.element)]), slot,
                          given ? (*top_size_side)[slot][0] : patchMapSize(options.map_size, std::max<size_t>(1, inView(f))),
                          given ? (*top_size_side)[slot][1] : topLevelMapSide(scene, f, f.views[v], options), true, {}});
        ++slot;
      }
    const size_t top = passes.size();
    // A top-level element outside the observer's view needs no map (its second-pass triangles are clipped).
    for (MapPass& mp : passes) mp.visible = topLevelVisible(*mp.owner, mp.view);
    const int max_depth = scene.render.max_depth;
    for (size_t i = 0; i < passes.size(); ++i) {
      if (!passes[i].visible) continue;
      const ElementFrame& owner = *passes[i].owner;
      const PatchView& pv = owner.views[passes[i].view];
      const int depth = passes[i].depth;
      for (size_t b = 0; b < frames.size(); ++b) {
        if (int(b) == owner.element || !mayBeInVolume(frames[b].world_pos, pv.volume.projection * pv.volume.view)) continue;
        const Element& el = scene.elements[b];
        const size_t views_needed = size_t(std::max(1, el.patches_u * el.patches_v));
        // The tracer absorbs at an element event with depth >= max_depth; a lens's back surface is the
        // event after its front, so the element is dark unless all its interfaces come before the limit.
        const bool too_deep = depth + interfaces(el) > max_depth;
        if (too_deep || visiblePasses() + views_needed > kMaxFirstPasses) {
          *budget_hit = *budget_hit || !too_deep;
          ++*dark;
          passes[i].nested.push_back({int(b), nullptr, 0});
          continue;
        }
        // The element as the owner's patch sees it: the geometry is the top-level frame's; each vertex's
        // incoming ray comes from where the owner's rays that reach it leave the owner (rayOrigins), and
        // the fit gives its own viewpoints and maps.
        auto nf = std::make_unique<ElementFrame>();
        nf->element = int(b);
        nf->grid = frames[b].grid;
        nf->world_pos = frames[b].world_pos;
        nf->world_normal = frames[b].world_normal;
        nf->patches_u = el.patches_u;
        nf->patches_v = el.patches_v;
        VertexStageOptions nested_opt = opts[b];
        nested_opt.viewer_clip = pv.volume.projection * pv.volume.view;  // seen by the owner's map camera
        nested_opt.tir_trace_depth = max_depth - depth;  // the events before this element are spent
        traceVertexRays(rays, *nf, pv.volume.eye, rayOrigins(owner, pv, nf->world_pos), nested_opt);
        fitPatchViews(scene, *nf, nested_opt);
        if (visiblePasses() + inView(*nf) > kMaxFirstPasses) {  // an automatic split needed more maps
          *budget_hit = true;
          ++*dark;
          passes[i].nested.push_back({int(b), nullptr, 0});
          continue;
        }
        const size_t first = slot;
        // The texture at half the parent's texture (it never reallocates), the rendered side at half the
        // parent's rendered side.
        const int size = nestedMapSize(passes[i].size), side = std::min(size, nestedMapSize(passes[i].side));
        for (size_t v = 0; v < nf->views.size(); ++v)  // a patch the owner's map camera cannot see: no map
          passes.push_back({nf.get(), v, depth + interfaces(el), slot++, size, side, nf->views[v].in_view, {}});
        passes[i].nested.push_back({int(b), nf.get(), first});
        nested_frames.push_back(std::move(nf));
      }
    }
    map_side.assign(passes.size(), 0);
    for (const MapPass& mp : passes) map_side[mp.slot] = mp.side;
    return passes.size() - top;
  }

  // Draws one element with its PVRR maps into the bound target, as seen by `cam`. More than three channels
  // (spectral): one draw per set of three, added into colour attachment 0 only (same vertices, depth test
  // LEQUAL); the seen point and the surface attachments come from the first draw.
  void drawPvrrElement(const ElementFrame& f, size_t first_slot, const PassCamera& cam, int seen_channel) {
    const Element& el = scene.elements[size_t(f.element)];
    const Vec3 anchor = Vec3(el.local_to_world[3]);
    const bool lens = el.type == ElementType::Lens;
    const size_t channels = f.rays.size();
    // RGB dispersion: its maps are planes, read one component per channel.
    const bool rgb = rgbLens(el, f);
    const Program* base = lens ? (rgb ? &lens_rgb_program : channels > 1 ? &lens3_program : &lens_program)
                               : (channels > 1 ? &pvrr3_program : &pvrr_program);
    if (cam.planes) {  // drawn into a planes map (only RGB scenes have them: never more than three channels)
      std::vector<std::string> d = {"#define MODE_PVRR", channels > 1 ? "#define CHANNELS 3" : "#define CHANNELS 1"};
      if (lens) d.push_back("#define LENS");
      if (rgb) d.push_back("#define RGB_CHANNELS");
      base = &planesVariant("element.vert", "element.frag", d);
    }
    const Program& p = *base;
    p.use();
    p.set("u_view_proj", toFloat(cam.view_proj));
    p.set("u_offset", glm::vec3(anchor - cam.origin));
    p.set("u_view_origin", glm::vec3(cam.rays_from));
    p.set("u_map", 0);
    p.set("u_seen_map", 1);
    p.set("u_map_g", 2);
    p.set("u_map_b", 3);
    setLights(p, cam.origin);
    setElementMaterial(p, el, f.element);
    // The seen point's channel: the one nearest the d line unless asked (the tracer's seen point is the d
    // line's ray; with RGB channels that is G exactly, with N spectral samples the nearest bin midpoint).
    size_t seen_c = channels / 2;
    if (seen_channel >= 0) {
      seen_c = std::min(size_t(seen_channel), channels - 1);
    } else if (f.channels.size() == channels) {
      auto off = [&](size_t c) {
        const double wl = f.channels[c].wavelength_nm > 0 ? f.channels[c].wavelength_nm : kLineD_nm;
        return std::abs(wl - kLineD_nm);
      };
      for (size_t c = 0; c < channels; ++c)
        if (off(c) < off(seen_c)) seen_c = c;
    }
    const size_t sets = channels > 1 ? (channels + 2) / 3 : 1;
    for (size_t v = 0; v < f.views.size(); ++v) {
      const PatchView& pv = f.views[v];
      const Framebuffer& map = *maps[first_slot + v];
      const int planes = map.colorFormat(0) == ColorFormat::R32F ? 3 : 1;  // colour attachments before the seen points
      if ((planes == 3) != rgb) throw Error("renderer: map slot " + std::to_string(first_slot + v) + " of " + el.name + " is " +
                                            (planes == 3 ? "in planes" : "RGBA") + " but the element's channels are " +
                                            (rgb ? "RGB" : "not RGB") + " (internal error)");
      if (cam.planes && sets > 1) throw Error("renderer: additive channel draws into a planes map (internal error)");
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, map.colorTexture(0));
      if (planes == 3) {
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, map.colorTexture(1));
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, map.colorTexture(2));
      }
      glActiveTexture(GL_TEXTURE1);
      if (options.seen_points) glBindTexture(GL_TEXTURE_2D, map.colorTexture(planes));
      p.set("u_seen_offset", glm::vec3(pv.volume.eye - cam.origin));
      // The map fills the lower-left mapTexels() of its texture: (s, t) in [0, 1]^2 of the volume scale to
      // that region, clamped half a texel inside it (as GL_CLAMP_TO_EDGE does at the texture's own edge).
      const std::array<int, 2> region = mapTexels(pv.volume, map_side[first_slot + v]);
      const glm::vec2 texels{float(region[0]), float(region[1])}, size{float(map.width()), float(map.height())};
      p.set("u_st_scale", texels / size);
      p.set("u_st_max", (texels - 0.5f) / size);
      for (size_t set = 0; set < sets; ++set) {
        MeshBuffers& mb = meshSlot();
        uploadPatch(mb, f, pv, anchor, set, seen_c);
        p.set("u_additive", set > 0 ? 1 : 0);
        if (set == 1) {
          glEnablei(GL_BLEND, 0);
          glBlendFunc(GL_ONE, GL_ONE);
          glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
          glColorMaski(2, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
          glDepthFunc(cam.reversed_depth ? GL_GEQUAL : GL_LEQUAL);
          glDepthMask(GL_FALSE);
        }
        draw(mb);
      }
      if (sets > 1) {
        glDisablei(GL_BLEND, 0);
        glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glColorMaski(2, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthFunc(cam.reversed_depth ? GL_GREATER : GL_LESS);
        glDepthMask(GL_TRUE);
      }
    }
    glActiveTexture(GL_TEXTURE0);
  }

  // An element met at the depth limit: black, its seen point its own surface (the tracer's "absorb").
  void drawDarkElement(const ElementFrame& f, const PassCamera& cam) {
    const Element& el = scene.elements[size_t(f.element)];
    const Vec3 anchor = Vec3(el.local_to_world[3]);
    const Program& plain = plainProgram(cam.planes);
    plain.use();
    plain.set("u_view_proj", toFloat(cam.view_proj));
    plain.set("u_offset", glm::vec3(anchor - cam.origin));
    plain.set("u_view_origin", glm::vec3(cam.rays_from));
    plain.set("u_dark", 1);
    setLights(plain, cam.origin);
    setElementMaterial(plain, el, f.element);
    MeshBuffers& mb = meshSlot();
    uploadElementGrid(mb, f, anchor);
    draw(mb);
  }

  // Sets the depth of the texels of map pass mp's region (bound, depth cleared) that its element cannot fetch
  // (MapFootprint of its patch's triangles at their texture coordinates, in every channel) to what no
  // fragment of the pass passes: 0 with GL_LESS, 1 with a reversed pass's GL_GREATER. Returns their count.
  int64_t closeUnreadTexels(const MapPass& mp, const std::array<int, 2>& region) {
    const PatchView& pv = mp.owner->views[mp.view];
    const MapFootprint fp = mapFootprint(pv.st, mp.owner->grid_patches[size_t(pv.patch)].triangles, region[0], region[1]);
    if (fp.all) return 0;
    std::vector<float> ndc;  // two triangles per closed run of a band
    auto close = [&](int x0, int x1, int y0, int y1) {
      if (x0 >= x1) return;
      const float ax = 2.0f * float(x0) / float(region[0]) - 1.0f, bx = 2.0f * float(x1) / float(region[0]) - 1.0f;
      const float ay = 2.0f * float(y0) / float(region[1]) - 1.0f, by = 2.0f * float(y1) / float(region[1]) - 1.0f;
      ndc.insert(ndc.end(), {ax, ay, bx, ay, bx, by, ax, ay, bx, by, ax, by});
    };
    for (size_t b = 0; b < fp.spans.size(); ++b) {
      const int y0 = int(b) * fp.band, y1 = std::min(y0 + fp.band, region[1]);
      const std::array<int, 2>& s = fp.spans[b];  // an empty band's span is {0, 0}: all of it closes
      close(0, s[0], y0, y1);
      close(s[1], region[0], y0, y1);
    }
    if (ndc.empty()) return 0;
    if (!mask_vao) {
      glGenVertexArrays(1, &mask_vao);
      glGenBuffers(1, &mask_vbo);
    }
    glBindVertexArray(mask_vao);
    glBindBuffer(GL_ARRAY_BUFFER, mask_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(ndc.size() * sizeof(float)), ndc.data(), GL_STREAM_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    mask_program.use();
    mask_program.set("u_ndc_z", pv.volume.backward ? 1.0f : -1.0f);  // window depth 1 or 0
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(ndc.size() / 2));
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindVertexArray(0);
    return int64_t(region[0]) * region[1] - fp.openTexels();
  }

  // Renders the planned first passes, deepest first; returns their cull counts. Passes of slots below
  // `whole_slots` (maps widened for reuse) draw every texel; the others skip what their element cannot read
  // (RendererOptions::skip_unread_texels), counted in `skipped` of `texels`.
  CullCount renderPasses(const std::vector<ElementFrame>& frames, size_t whole_slots, int64_t* skipped, int64_t* texels) {
    CullCount count;
    *skipped = *texels = 0;
    for (size_t i = passes.size(); i-- > 0;) {
      const MapPass& mp = passes[i];
      const PatchView& pv = mp.owner->views[mp.view];
      const bool planes = rgbLens(scene.elements[size_t(mp.owner->element)], *mp.owner);
      const Framebuffer& t = mapTarget(mp.slot, mp.size, planes);
      if (!mp.visible) continue;
      // No colour clear: the sky covers every texel nothing else does (drawEnvironment).
      const std::array<int, 2> region = mapTexels(pv.volume, mp.side);
      t.bindRegionClearDepth(region[0], region[1], pv.volume.backward ? 0.0f : 1.0f);
      *texels += int64_t(region[0]) * region[1];
      if (options.skip_unread_texels && mp.slot >= whole_slots) *skipped += closeUnreadTexels(mp, region);
      // In a reversed (zooming) map the rays come from the mirror, not from the viewpoint.
      const Vec3 element_centre = Vec3(scene.elements[size_t(mp.owner->element)].local_to_world[3]);
      count.add(drawEnvironment(pv.volume.view, pv.volume.projection, pv.volume.eye, pv.volume.backward,
                                pv.volume.backward ? &element_centre : nullptr, planes));
      PassCamera cam;
      cam.planes = planes;
      cam.origin = pv.volume.eye;
      cam.view_proj = relativeViewProj(pv.volume.projection, pv.volume.view, pv.volume.eye);
      cam.rays_from = pv.volume.backward ? element_centre - pv.volume.eye : Vec3(0.0);
      cam.reversed_depth = pv.volume.backward;
      for (const NestedDraw& nd : mp.nested) {
        t.bindRegion(region[0], region[1]);
        if (nd.frame) drawPvrrElement(*nd.frame, nd.first_slot, cam, -1);
        else drawDarkElement(frames[size_t(nd.element)], cam);
      }
    }
    glDepthFunc(GL_LESS);
    return count;
  }

  RasterFrame render(RenderMode mode, FrameCache* cache);
};

Renderer::Renderer(const Scene& scene, const RayScene& rays, RendererOptions options)
    : impl_(std::make_unique<Impl>(scene, rays, std::move(options))) {}
Renderer::~Renderer() = default;

RasterFrame Renderer::render(RenderMode mode, FrameCache* cache) {
  PVRR_CHECK(isRasterMode(mode), "(raytrace is the reference tracer's mode)");
  return impl_->render(mode, cache);
}
void Renderer::setReadBack(bool on) { impl_->options.read_back = on; }

RasterFrame Renderer::Impl::render(RenderMode mode, FrameCache* cache) {
  const auto frame_start = Clock::now();
  const Observer& ob = scene.observer;
  RasterFrame out;
  out.width = ob.width;
  out.height = ob.height;
  const bool has_lens = std::any_of(scene.elements.begin(), scene.elements.end(),
                                    [](const Element& e) { return e.type == ElementType::Lens; });
  const size_t n_el = scene.elements.size();
  next_mesh = 0;

  // --- CPU stages (pvrr mode) ---
  std::vector<ElementFrame> frames;
  std::vector<VertexStageOptions> opts;
  bool skip_first_pass = false;
  bool continuing = false;  // a cache that holds an earlier frame: maps are widened for reuse
  if (mode == RenderMode::Pvrr && n_el > 0) {
    frames.resize(n_el);
    // Each element's views are fitted to what the observer sees of it.
    const Mat4 observer_projection = ob.visibilityProjection(), observer_clip = observer_projection * ob.view();
    for (size_t e = 0; e < n_el; ++e) {
      opts.push_back(optionsFor(e));
      opts.back().viewer_clip = observer_clip;
    }
    // Eye-fixed caching (paper 5): an element whose pose relative to the eye is unchanged keeps its rays
    // (in the eye's frame) and its fitted viewpoints; only the scene intersections and texture coordinates
    // are redone, after moving the cached frame rigidly with the eye.
    const Mat4 view = ob.view();
    const Mat4 motion = glm::inverse(view) * (cache ? cache->view : Mat4(1.0));
    auto same = [](const Mat4& a, const Mat4& b) {
      double d = 0;
      for (int c = 0; c < 4; ++c) d = std::max(d, glm::length(a[c] - b[c]));
      return d < 1e-12;  // a rigid pose re-composed in double differs by a few ulps, never more
    };
    std::vector<bool> reuse(n_el, false);
    const bool same_projection = cache && same(cache->projection, observer_projection);
    for (size_t e = 0; e < n_el; ++e)
      reuse[e] = cache && cache->valid && same_projection && cache->elements.size() == n_el &&
                 sameChannels(cache->elements[e].channels, opts[e].channels) &&
                 same(cache->element_to_eye[e], view * scene.elements[e].local_to_world);
    const bool all_reused = std::all_of(reuse.begin(), reuse.end(), [](bool b) { return b; });
    // Nothing moved, and the maps this renderer holds are the ones the cached frame was drawn with.
    const bool nothing_moved = all_reused && same(motion, Mat4(1.0)) && !cache->environment_changed &&
                               cache->frame_serial == first_pass_serial;
    const std::string cached = "eye-fixed cache: no element moved relative to the eye";
    auto t0 = Clock::now();
    double refraction_ms = 0, texcoord_ms = 0;
    bool any_texcoords = false;
    size_t mirror_rays = 0, beside = 0;  // traced this frame; beside: VertexStageOptions::beside_own_mirror
    for (size_t e = 0; e < n_el; ++e) {
      if (reuse[e]) {
        frames[e] = cache->elements[e];
        if (!nothing_moved) {
          moveRigidly(frames[e], motion);
          updateTextureCoordinates(rays, frames[e]);
          texcoord_ms += frames[e].rays_ms;
          any_texcoords = true;
        }
        continue;
      }
      frames[e] = prepareElement(scene, int(e), &grid_cache.get(scene, int(e)));
      traceVertexRays(rays, frames[e], ob.eye, opts[e]);
      if (scene.elements[e].type == ElementType::Lens) refraction_ms += frames[e].rays_ms;
      else mirror_rays += frames[e].rays.size() * frames[e].world_pos.size(), beside += size_t(frames[e].rays_beside);
    }
    const double cpu_ms = msSince(t0);
    if (all_reused) out.stages.skipped("vertex-rays", cached);
    else
      out.stages.ran("vertex-rays", cpu_ms - texcoord_ms, -1,
                     mirror_rays == 0 ? std::string()
                                      : std::to_string(beside) + " of " + std::to_string(mirror_rays) +
                                            " mirror rays traced beside their own mirror");
    if (!has_lens) out.stages.skipped("refraction", "no lens in the scene");
    else if (all_reused) out.stages.skipped("refraction", cached);
    else out.stages.ran("refraction", refraction_ms);
    t0 = Clock::now();
    for (size_t e = 0; e < n_el; ++e)
      if (!reuse[e]) fitPatchViews(scene, frames[e], opts[e]);
    if (all_reused) out.stages.skipped("viewpoint-fit", cached);
    else out.stages.ran("viewpoint-fit", msSince(t0));
    if (any_texcoords) out.stages.ran("texture-coordinates", texcoord_ms);
    else out.stages.skipped("texture-coordinates", nothing_moved ? "nothing moved since the last frame"
                                                                 : "computed with the viewpoint fit");
    size_t most_channels = 1;
    bool spectral = false;
    for (const ElementFrame& f : frames) {
      most_channels = std::max(most_channels, f.rays.size());
      const bool rgb = f.channels.size() == 3 && f.channels[0].wavelength_nm == kRgbWavelengths_nm[0] &&
                       f.channels[1].wavelength_nm == kRgbWavelengths_nm[1] &&
                       f.channels[2].wavelength_nm == kRgbWavelengths_nm[2];
      spectral = spectral || (f.channels.size() > 1 && !rgb);
    }
    if (most_channels > 1) {
      const size_t sets = (most_channels + 2) / 3;
      out.stages.ran("colour-channels", 0, int(most_channels),
                     std::to_string(most_channels) + (spectral ? " spectral samples" : " RGB channels (C, d, F lines)") +
                         " from one shared first pass, in " + std::to_string(sets) +
                         (sets == 1 ? " draw" : " additive draws") + " per patch");
    } else {
      out.stages.skipped("colour-channels", has_lens ? "dispersion off: one colour pass" : "no lens: one colour pass");
    }
    skip_first_pass = nothing_moved;
    continuing = cache && cache->valid;
  } else {
    const std::string why = n_el == 0 ? "no mirror or lens in the scene" : std::string("mode ") + nameOf(mode);
    out.stages.skipped("vertex-rays", mode == RenderMode::Impostor && n_el > 0
                                          ? why + ": each fragment reflects or refracts its own ray (second pass)"
                                          : why);
    if (mode == RenderMode::Impostor && has_lens)
      out.stages.skipped("refraction", why + ": per fragment, through the lens's refractor height maps (second pass)");
    else
      out.stages.skipped("refraction", has_lens ? why : "no lens in the scene");
    out.stages.skipped("viewpoint-fit", why);
    out.stages.skipped("texture-coordinates", why);
    if (mode == RenderMode::Impostor && has_lens) {
      int most = 1;
      bool spectral = false;
      for (size_t e = 0; e < n_el; ++e) {
        const size_t n = dispersionChannels(scene, int(e)).size();
        most = std::max(most, n > 1 ? 3 : 1);
        spectral = spectral || n > 3;
      }
      if (most > 1)
        out.stages.ran("colour-channels", 0, most,
                       std::string("R, G and B refracted with their own index per fragment") +
                           (spectral ? " (spectral dispersion approximated by the C, d and F lines in mode impostor)" : ""));
      else
        out.stages.skipped("colour-channels", "dispersion off: one wavelength (the d line)");
    } else {
      out.stages.skipped("colour-channels", why);
    }
  }

  // --- first pass (and the nested passes of elements seen in other elements' maps) ---
  auto t0 = Clock::now();
  std::function<CullCount()> second_layers;  // impostor mode with two layers: draws the second layers' cubes
  std::vector<size_t> top_slot(n_el, 0);  // map slot of frames[e].views[0] (pvrr mode)
  {
    size_t slot = 0;
    for (size_t e = 0; e < frames.size(); ++e) {
      top_slot[e] = slot;
      slot += frames[e].views.size();
    }
  }
  // Map reuse (RendererOptions::map_reuse_margin_deg): a frame that follows another draws from the maps of
  // an earlier one while its views stay inside them; otherwise its maps are drawn widened by the margin.
  const bool reuse_on = mode == RenderMode::Pvrr && !frames.empty() && options.map_reuse_margin_deg > 0 && continuing;
  std::string reuse_note;
  if (reuse_on && !skip_first_pass && !cache->environment_changed && reuseMaps(frames, *cache, &reuse_note)) {
    skip_first_pass = true;
    ++cache->maps_age;
  } else if (reuse_on && skip_first_pass && !cache->maps.empty()) {
    ++cache->maps_age;  // nothing moved: the same maps, one frame older
  }
  // Maps are widened for reuse unless the last first pass could not be kept (nested passes, dark elements)
  // or no view can be (reversed maps are never widened nor reused).
  const bool any_forward = std::any_of(frames.begin(), frames.end(), [](const ElementFrame& f) {
    return std::any_of(f.views.begin(), f.views.end(), [](const PatchView& v) { return !v.volume.backward; });
  });
  const bool widen = reuse_on && !cache->last_plan_nested && any_forward;
  if (mode == RenderMode::Pvrr && !frames.empty() && skip_first_pass) {
    const std::string why = !reuse_note.empty() ? reuse_note
                                                : "eye-fixed cache: neither the elements nor the environment moved relative to the eye";
    out.stages.skipped("first-pass", why);
    out.stages.skipped("nested-passes", why);
  } else if (mode == RenderMode::Pvrr && !frames.empty()) {
    size_t dark = 0;
    bool budget_hit = false;
    std::vector<std::array<int, 2>> widened;  // per top-level slot: texture size, rendered side
    if (widen) widened = widenMaps(frames);
    const size_t nested = planPasses(frames, opts, &dark, &budget_hit, widen ? &widened : nullptr);
    const double plan_ms = msSince(t0);
    int deepest = 0, rendered = 0;
    for (const MapPass& mp : passes) {
      deepest = std::max(deepest, mp.depth);
      rendered += mp.visible;
    }
    const auto t1 = Clock::now();
    // The maps change from here: any cache's record of them is void, even if a pass fails.
    first_pass_serial = nextFirstPassSerial();
    if (cache) cache->maps.clear();
    int64_t unread = 0, texels = 0;
    const CullCount culled = renderPasses(frames, widen ? widened.size() : 0, &unread, &texels);
    glFinish();
    if (cache) {
      cache->last_plan_nested = nested > 0 || dark > 0;
      if (widen && !cache->last_plan_nested) {
        for (size_t i = 0; i < widened.size(); ++i) {
          const MapPass& mp = passes[i];
          cache->maps.push_back({mp.owner->element, mp.view, mp.owner->views[mp.view].volume, mp.side, mp.visible});
        }
        cache->maps_serial = first_pass_serial;
        cache->maps_age = 0;
      }
    }
    // The note: how many maps of which size (and which are R, G, B planes), and what was not rendered.
    std::map<std::array<int, 3>, int, std::greater<std::array<int, 3>>> sizes;
    for (const MapPass& mp : passes)
      if (mp.visible) {
        const std::array<int, 2> t = mapTexels(mp.owner->views[mp.view].volume, mp.side);
        ++sizes[{t[0], t[1], maps[mp.slot]->colorFormat(0) == ColorFormat::R32F}];
      }
    std::string note;
    for (const auto& [texels, n] : sizes)
      note += (note.empty() ? "" : ", ") + std::to_string(n) + " x " + std::to_string(texels[0]) + "x" +
              std::to_string(texels[1]) + (texels[2] ? " RGB planes" : "");
    if (widen)
      note += "; widened up to " + fmt("%.3g", options.map_reuse_margin_deg) + " deg for reuse (" +
              (reuse_note.empty() ? std::string("the environment changed") : reuse_note) + ")";
    else if (reuse_on)
      note += any_forward ? "; not widened for reuse: the last first pass had nested passes or elements drawn dark"
                          : "; not widened for reuse: reversed (zooming) maps are not reused";
    if (rendered != int(passes.size()))
      appendNote(note, std::to_string(passes.size() - size_t(rendered)) +
                           " map(s) of elements outside the observer's view or beyond the depth limit not rendered");
    if (unread > 0)
      appendNote(note, fmt("%.2g", 100.0 * double(unread) / double(texels)) +
                           " % of map texels left unshaded (no element reads them)");
    appendNote(note, cullNote(culled));
    out.stages.ran("first-pass", msSince(t1), rendered, note);
    const std::string dark_note =
        dark == 0 ? "" : std::to_string(dark) + " element(s) in a map drawn dark (" +
                             (budget_hit ? "the budget of " + std::to_string(kMaxFirstPasses) + " first passes"
                                         : "render.max_depth = " + std::to_string(scene.render.max_depth)) + ")";
    if (nested > 0)
      out.stages.ran("nested-passes", plan_ms, int(nested),
                     std::to_string(nested) + " nested first pass(es), maps down to depth " + std::to_string(deepest) +
                         (dark_note.empty() ? "" : "; " + dark_note));
    else if (n_el == 1)
      out.stages.skipped("nested-passes", std::string("one ") + (has_lens ? "lens" : "mirror") + ": no nesting");
    else if (dark > 0)
      out.stages.skipped("nested-passes", dark_note);
    else
      out.stages.skipped("nested-passes", "no element is inside another element's view volume");
  } else if ((mode == RenderMode::Envmap || mode == RenderMode::Impostor) && n_el > 0) {
    while (cubes.size() < n_el) cubes.push_back(std::make_unique<CubeTarget>());
    const int layers = impostorLayers(mode);
    while (layers > 1 && cubes1.size() < n_el) cubes1.push_back(std::make_unique<CubeTarget>());
    if (layers == 1) cubes1.clear();  // a scene without the second layers holds none
    const int layer1_size = std::max(16, options.map_size / 2);
    CullCount culled;
    // Impostor cube maps hold the seen points (each direction's distance) even in a colour-only frame, and with
    // other elements in them (cubeElements) a third cube of their normals and indices.
    const bool with_seen = mode == RenderMode::Impostor;
    const int follow = cubeElements(mode);
    const bool lens_in_cubes = lensInCubes(mode);
    // The elements drawn in other elements' cubes: the mirrors, and the lens if it is the only one.
    auto inCubes = [this, follow, lens_in_cubes](size_t m) {
      return follow > 0 && (scene.elements[m].type == ElementType::Mirror || lens_in_cubes);
    };
    std::vector<GLenum> formats{GL_RGBA16F};
    if (options.seen_points || with_seen) formats.push_back(GL_RGBA32F);
    if (follow > 0) formats.push_back(GL_RGBA32F);
    int height_maps = 0, surface_maps = 0;
    for (size_t e = 0; e < n_el && mode == RenderMode::Impostor; ++e) {
      if (scene.elements[e].type == ElementType::Lens) height_maps += updateLensMaps(e);
      else surface_maps += updateMirrorMaps(e);
    }
    // The elements other cubes show: each mesh uploaded once (element_meshes slots).
    std::vector<size_t> cube_mesh(n_el, 0);
    int drawn_in_cubes = 0;
    for (size_t m = 0; m < n_el; ++m) {
      if (!inCubes(m)) continue;
      const ElementFrame f = prepareElement(scene, int(m), &grid_cache.get(scene, int(m)));
      cube_mesh[m] = next_mesh;
      uploadElementGrid(meshSlot(), f, Vec3(scene.elements[m].local_to_world[3]));
    }
    // No cube stays bound to the units the element programs read while cubes are drawn into.
    for (GLenum unit : {GL_TEXTURE0, GL_TEXTURE1}) {
      glActiveTexture(unit);
      glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    }
    glActiveTexture(GL_TEXTURE0);
    // Layer 0 of element e's cubes: the nearest surfaces. Layer 1 (seeds 001, depth peeling, at half the size):
    // the nearest beyond them, what an occluder near the element hides from its origin; where nothing lies
    // beyond, the first layer's own texel (shaders/sky.frag, FIRST_LAYER). Layer 1 is drawn in the second pass,
    // and only if some pixel's search needs it (second_layers).
    auto drawCubes = [this, n_el, inCubes, with_seen, cube_mesh](size_t e, int layer) {
      const Vec3 centre = Vec3(scene.elements[e].local_to_world[3]);
      const double near_m = 1e-3, far_m = 2.0 * (scene.boundsRadius() + glm::length(centre - scene.bounds_min)) + 1.0;
      const Mat4 proj = glm::perspective(kPi / 2, 1.0, near_m, far_m);
      CubeTarget& c = layer ? *cubes1[e] : *cubes[e];
      if (layer) {  // the first layer's seen points, colour and normals (shaders/sky.frag, FIRST_LAYER)
        const std::vector<GLuint>& first = cubes[e]->colors;
        const std::pair<int, GLuint> binds[3] = {
            {kPeelUnit, first[1]}, {kFirstCubeUnit, first[0]}, {kFirstCubeUnit + 1, first.size() > 2 ? first[2] : 0}};
        for (const auto& [unit, tex] : binds) {
          glActiveTexture(GLenum(GL_TEXTURE0 + unit));
          glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
        }
        glActiveTexture(GL_TEXTURE0);
      }
      CullCount culled;
      int drawn = 0;
      for (int face = 0; face < 6; ++face) {
        c.selectFace(face);
        const Mat4 view = glm::lookAt(centre, centre + kCubeDir[face], kCubeUp[face]);
        for (size_t m = 0; m < n_el; ++m)
          if (m != e && inCubes(m)) {
            drawCubeElement(m, relativeViewProj(proj, view, centre), centre, element_meshes[cube_mesh[m]], layer > 0);
            drawn += face == 0;
          }
        culled.add(drawEnvironment(view, proj, centre, false, nullptr, false, with_seen, layer > 0));
      }
      if (layer) {
        for (int unit : {kPeelUnit, kFirstCubeUnit, kFirstCubeUnit + 1}) {
          glActiveTexture(GLenum(GL_TEXTURE0 + unit));
          glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
        }
        glActiveTexture(GL_TEXTURE0);
      }
      return std::make_pair(culled, drawn);
    };
    for (size_t e = 0; e < n_el; ++e) {
      if (cubes[e]->size != options.map_size || cubes[e]->colors.size() != formats.size())
        cubes[e]->create(options.map_size, formats);
      // The second layer's targets exist from here on: the element programs bind them.
      if (layers > 1 && (cubes1[e]->size != layer1_size || cubes1[e]->colors.size() != formats.size()))
        cubes1[e]->create(layer1_size, formats);
      const auto [c, drawn] = drawCubes(e, 0);
      culled.add(c);
      drawn_in_cubes += drawn;
    }
    if (layers > 1)
      second_layers = [this, n_el, drawCubes] {
        CullCount culled;
        for (size_t e = 0; e < n_el; ++e) culled.add(drawCubes(e, 1).first);
        return culled;
      };
    glFinish();
    std::string note = mode == RenderMode::Impostor ? "distance impostors: colour and seen-point cube maps" : "";
    if (layers > 1)
      appendNote(note, "two layers each where needed (the second depth-peeled, " + std::to_string(layer1_size) +
                           "^2 a face)");
    else if (mode == RenderMode::Impostor && scene.render.impostor_layers > 1)
      appendNote(note, "one layer each: too few texture units for the second layers' cubes");
    if (follow > 0) appendNote(note, "normal and index cube maps of the elements in them");
    if (height_maps > 0) appendNote(note, "refractor height maps of " + std::to_string(height_maps) + " lens(es) built");
    if (surface_maps > 0) appendNote(note, "surface maps of " + std::to_string(surface_maps) + " mirror(s) built");
    appendNote(note, cullNote(culled));
    out.stages.ran("first-pass", msSince(t0), -1, note);
    if (follow > 0)
      out.stages.ran("nested-passes", 0, drawn_in_cubes,
                     std::to_string(drawn_in_cubes) + " element(s) drawn into other elements' cube maps, with "
                     "their normals and index (distance-normal impostors), followed per fragment up to "
                     "render.max_depth = " + std::to_string(scene.render.max_depth) +
                         (lens_in_cubes ? "; the lens refracted through its height maps there"
                          : lensCount() > 0 ? "; lenses are absent from other elements' cube maps (more than one)"
                                            : ""));
    else if (n_el == 1)
      out.stages.skipped("nested-passes", std::string("one ") + (has_lens ? "lens" : "mirror") + ": no nesting");
    else if (mode == RenderMode::Impostor && lensCount() == n_el)
      out.stages.skipped("nested-passes", "mode impostor: lenses are absent from other elements' cube maps");
    else if (mode == RenderMode::Impostor)
      out.stages.skipped("nested-passes", "mode impostor: more than " + std::to_string(kMaxCubeElements) +
                                              " elements (or too few texture units): other elements are absent from "
                                              "the cube maps");
    else
      out.stages.skipped("nested-passes", std::string("mode ") + nameOf(mode) + ": other elements are absent from the cube maps");
  } else {
    out.stages.skipped("first-pass", n_el == 0 ? "no mirror or lens in the scene" : std::string("mode ") + nameOf(mode));
    out.stages.skipped("nested-passes", n_el == 0 ? "no mirror or lens in the scene" : "mode raster");
  }

  // The cache takes this frame whole, once its maps are drawn: the poses, and the elements with the volumes
  // and texture coordinates of the maps now held.
  if (cache && mode == RenderMode::Pvrr && n_el > 0) {
    const Mat4 view = ob.view();
    cache->element_to_eye.resize(n_el);
    for (size_t e = 0; e < n_el; ++e) cache->element_to_eye[e] = view * scene.elements[e].local_to_world;
    cache->view = view;
    cache->projection = ob.visibilityProjection();
    cache->elements = frames;
    cache->frame_serial = first_pass_serial;
    cache->valid = true;
  }

  // --- second pass ---
  t0 = Clock::now();
  // A picture-only frame goes into 16 bits a channel (RendererOptions::seen_points), unless an element is
  // drawn in several additive draws (more than three channels): their partial sums can be negative or above
  // 1 (spectral weights), and a normalised target would clamp each before the sum.
  const bool additive = mode == RenderMode::Pvrr && std::any_of(frames.begin(), frames.end(), [](const ElementFrame& f) {
                          return f.rays.size() > 3;
                        });
  const ColorFormat colour = options.seen_points || additive ? ColorFormat::RGBA32F : ColorFormat::RGBA16;
  const int follow = cubeElements(mode);  // impostor: the elements the fragments follow through their cubes
  const int layers = impostorLayers(mode);
  if (!frame_target || frame_target->width() != ob.width || frame_target->height() != ob.height ||
      frame_target->colorFormat(0) != colour)
    frame_target = std::make_unique<Framebuffer>(
        ob.width, ob.height,
        options.seen_points ? std::vector<ColorFormat>{colour, ColorFormat::RGBA32F, ColorFormat::RGBA32F}
                            : std::vector<ColorFormat>{colour},
        DepthFormat::Depth32F);
  frame_target->clearDepth();  // no colour clear: the sky covers every pixel nothing else does
  // The elements come first: the depth state must not depend on what an earlier pass (or none) left.
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  const double near_m = 1e-3;
  const double far_m = 4.0 * (scene.boundsRadius() + glm::length(ob.eye - 0.5 * (scene.bounds_min + scene.bounds_max))) + 1.0;
  const Mat4 view = ob.view(), proj = ob.projection(near_m, far_m);
  const Mat4 vp = relativeViewProj(proj, view, ob.eye);
  PassCamera eye_cam;
  eye_cam.origin = ob.eye;
  eye_cam.view_proj = vp;
  // Element e drawn by the plain, envmap or impostor program from its mesh in element_meshes[element_slot[e]].
  // Impostor with two layers (layer_draw): 0 the first draw, which leaves the pixels whose search ends off a
  // surface in the first layer (it discards them, writing no depth); 2 a probe, which counts those pixels (no
  // colour, no depth: only what passes the depth test is shaded, and it returns at once); 1 the second draw
  // (LAYER_MARCH), which passes the depth test only there: where the first draw kept a fragment, the same
  // fragment has the same depth (element.vert's invariant position). A renderer that runs every path of a
  // shader with the lanes that do not take it masked off (llvmpipe) pays the second layer's search only there:
  // it tests depth before a shader that may discard, and skips blocks of pixels that all fail.
  std::vector<size_t> element_slot(n_el, 0);
  auto drawElement = [&](size_t e, int layer_draw) {
    const Element& el = scene.elements[e];
    const Vec3 anchor = Vec3(el.local_to_world[3]);
    const bool lens = el.type == ElementType::Lens;
    const Program& p = mode == RenderMode::Raster ? plain_program
                       : mode == RenderMode::Impostor
                           ? impostorProgram(lens, impostorChannels(e), follow, lensInCubes(mode), layers, layer_draw)
                           : (lens ? lens_envmap_program : envmap_program);
    p.use();
    p.set("u_view_proj", toFloat(vp));
    p.set("u_offset", glm::vec3(anchor - ob.eye));
    p.set("u_view_origin", glm::vec3(0.0f));
    setLights(p, ob.eye);
    setElementMaterial(p, el, int(e));
    if (mode == RenderMode::Raster) p.set("u_dark", 0);
    if (mode == RenderMode::Envmap || mode == RenderMode::Impostor) {
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[0]);
      glActiveTexture(GL_TEXTURE1);
      if (cubes[e]->colors.size() > 1) glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[1]);
      glActiveTexture(GL_TEXTURE0);
      p.set("u_cube", 0);
      p.set("u_seen_cube", 1);
      p.set("u_seen_offset", glm::vec3(anchor - ob.eye));
    }
    if (layers > 1 && follow == 0) {  // one element: its second layer after its own maps
      for (int a = 0; a < 2; ++a) {
        glActiveTexture(GLenum(GL_TEXTURE0 + kFirstCubeUnit + a));
        glBindTexture(GL_TEXTURE_CUBE_MAP, cubes1[e]->colors[size_t(a)]);
      }
      glActiveTexture(GL_TEXTURE0);
      p.set("u_cube1", kFirstCubeUnit);
      p.set("u_seen_cube1", kFirstCubeUnit + 1);
    }
    if (mode == RenderMode::Impostor && !lens) setMirrorMaps(p, e);
    if (follow > 0) setCubeElements(p, e, ob.eye, layers);
    if (mode == RenderMode::Impostor && lens) setLensMaps(p, e);
    if (mode == RenderMode::Impostor)
      p.set("u_seen_channel", options.seen_channel < 0 ? 1 : std::min(options.seen_channel, 2));
    draw(element_meshes[element_slot[e]]);
  };
  for (size_t e = 0; e < n_el; ++e) {
    frame_target->bind();
    if (mode == RenderMode::Pvrr) {
      if (beyondDepth(frames[e])) drawDarkElement(frames[e], eye_cam);
      else drawPvrrElement(frames[e], top_slot[e], eye_cam, options.seen_channel);
    } else {
      ElementFrame f = prepareElement(scene, int(e), &grid_cache.get(scene, int(e)));
      if (scene.elements[e].type == ElementType::Lens && mode == RenderMode::Envmap)
        traceVertexRays(rays, f, ob.eye, VertexStageOptions{});
      element_slot[e] = next_mesh;
      uploadElementGrid(meshSlot(), f, Vec3(scene.elements[e].local_to_world[3]));
      drawElement(e, 0);
    }
  }
  // The second layers, where some pixel needs them: the probe counts each element's pixels left by its first
  // draw; the second layers' cubes are drawn if there are any, and the second draw of each such element.
  std::string layer_note;
  if (second_layers) {
    const auto t_layers = Clock::now();
    std::vector<GLuint> queries(n_el);
    glGenQueries(GLsizei(n_el), queries.data());
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    for (size_t e = 0; e < n_el; ++e) {
      glBeginQuery(GL_SAMPLES_PASSED, queries[e]);
      drawElement(e, 2);
      glEndQuery(GL_SAMPLES_PASSED);
    }
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    std::vector<GLuint> left(n_el, 0);
    GLuint total = 0;
    for (size_t e = 0; e < n_el; ++e) {
      glGetQueryObjectuiv(queries[e], GL_QUERY_RESULT, &left[e]);
      total += left[e];
    }
    glDeleteQueries(GLsizei(n_el), queries.data());
    if (total > 0) {
      // No cube stays bound to a unit while cubes are drawn into (the element programs bound the second
      // layers from kFirstCubeUnit on).
      for (int unit = kFirstCubeUnit; unit < std::min(max_texture_units, kFirstCubeUnit + 6 * int(n_el)); ++unit) {
        glActiveTexture(GLenum(GL_TEXTURE0 + unit));
        glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
      }
      glActiveTexture(GL_TEXTURE0);
      const CullCount layer_culled = second_layers();
      frame_target->bind();
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
      for (size_t e = 0; e < n_el; ++e)
        if (left[e] > 0) drawElement(e, 1);
      glFinish();
      layer_note = "second layers drawn (" + fmt("%.1f", msSince(t_layers)) + " ms: their cubes, " +
                   cullNote(layer_culled) + ", and the second draws): " + std::to_string(total) +
                   " pixel(s) whose first-layer search ended off a surface";
    } else {
      layer_note = "second layers not drawn: every pixel's search ended on a surface in the first layer";
    }
  }
  // The environment after the elements: behind a lens or mirror it fails the early depth test, unshaded.
  frame_target->bind();
  const CullCount culled = drawEnvironment(view, proj, ob.eye);
  glFinish();
  checkGlError("rendering a frame");
  std::string second_note = cullNote(culled);
  appendNote(second_note, layer_note);
  out.stages.ran("second-pass", msSince(t0), -1, second_note);
  if (options.seen_points)
    out.stages.ran("seen-points", 0, -1, "world-position attachments in every pass (for accuracy reports)");
  else
    out.stages.skipped("seen-points", "not requested: colour only (no seen-point attachments)");
  out.elements = std::move(frames);

  if (options.read_back && !options.seen_points) {
    const std::vector<float> color = frame_target->readFloat4(0);  // rows top-down
    out.color.resize(size_t(ob.width) * size_t(ob.height));
    for (size_t i = 0; i < out.color.size(); ++i) out.color[i] = Vec3(color[4 * i], color[4 * i + 1], color[4 * i + 2]);
  } else if (options.read_back) {
    const std::vector<float> color = frame_target->readFloat4(0), seen = frame_target->readFloat4(1),
                             surf = frame_target->readFloat4(2);  // rows top-down
    const size_t n = size_t(ob.width) * size_t(ob.height);
    out.color.resize(n);
    out.seen.resize(n);
    out.element.resize(n);
    out.element_point.resize(n);
    for (int y = 0; y < ob.height; ++y) {
      for (int x = 0; x < ob.width; ++x) {
        const size_t dst = size_t(y) * size_t(ob.width) + size_t(x), src = 4 * dst;
        out.color[dst] = Vec3(color[src], color[src + 1], color[src + 2]);
        out.seen[dst] = ob.eye + Vec3(seen[src], seen[src + 1], seen[src + 2]);
        const int id = int(std::lround(surf[src + 3])) - 1;
        out.element[dst] = id;
        out.element_point[dst] = ob.eye + Vec3(surf[src], surf[src + 1], surf[src + 2]);
      }
    }
  }
  out.frame_ms = msSince(frame_start);
  return out;
}

}  // namespace pvrr::gl

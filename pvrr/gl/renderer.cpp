#include "pvrr/gl/renderer.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <chrono>

#include "cad/error.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/program.h"

namespace pvrr::gl {

RasterMode parseRasterMode(const std::string& mode) {
  if (mode == "raster") return RasterMode::Raster;
  if (mode == "pvrr") return RasterMode::Pvrr;
  if (mode == "envmap") return RasterMode::Envmap;
  throw Error("mode: expected one of pvrr, raster, envmap, raytrace; got \"" + mode + "\"");
}

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
      // Colour and seen points both filter linearly (see the 2D maps below).
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

// Cube-map faces in GL order (+X, -X, +Y, -Y, +Z, -Z): view direction and up vector.
const Vec3 kCubeDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const Vec3 kCubeUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};

}  // namespace

struct Renderer::Impl {
  const Scene& scene;
  const RayScene& rays;
  RendererOptions options;
  Program env_program = makeProgram("env.vert", "env.frag");
  Program sky_program = makeProgram("sky.vert", "sky.frag");
  Program plain_program = makeProgram("element.vert", "element.frag", {"#define MODE_PLAIN"});
  Program envmap_program = makeProgram("element.vert", "element.frag", {"#define MODE_ENVMAP"});
  Program lens_envmap_program = makeProgram("element.vert", "element.frag", {"#define MODE_ENVMAP", "#define LENS"});
  Program pvrr_program = makeProgram("element.vert", "element.frag", {"#define MODE_PVRR", "#define CHANNELS 1"});
  Program pvrr3_program = makeProgram("element.vert", "element.frag", {"#define MODE_PVRR", "#define CHANNELS 3"});
  Program lens_program = makeProgram("element.vert", "element.frag", {"#define MODE_PVRR", "#define CHANNELS 1", "#define LENS"});
  Program lens3_program = makeProgram("element.vert", "element.frag", {"#define MODE_PVRR", "#define CHANNELS 3", "#define LENS"});
  GLuint empty_vao = 0;
  std::vector<MeshBuffers> env_meshes;
  std::vector<Texture> textures;  // environment textures, in Scene::textures order
  std::unique_ptr<Framebuffer> frame_target;      // the second pass: colour, seen point, surface point
  std::vector<std::unique_ptr<Framebuffer>> maps;  // first-pass maps, one per patch view (reused)
  std::vector<std::unique_ptr<CubeTarget>> cubes;  // envmap cubes, one per element
  std::vector<MeshBuffers> element_meshes;     // per (element, patch) in pvrr mode; per element otherwise

  Impl(const Scene& s, const RayScene& r, RendererOptions o) : scene(s), rays(r), options(std::move(o)) {
    glGenVertexArrays(1, &empty_vao);
    for (const pvrr::Texture& t : scene.textures) {
      ImageRGB8 image;
      image.width = t.width;
      image.height = t.height;
      image.rgb = t.rgb;
      // sRGB, flipped so v = 0 is the image's bottom row, no mipmaps: bilinear sampling with repeat wrapping,
      // exactly what the tracer does (pvrr/shading.cpp).
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
    }
    checkGlError("uploading the environment");
  }

  ~Impl() {
    for (auto& m : env_meshes) m.release();
    for (auto& m : element_meshes) m.release();
    if (empty_vao) glDeleteVertexArrays(1, &empty_vao);
  }

  void setLights(const Program& p, const Vec3& origin) const {
    int types[8] = {};
    float vecs[24] = {}, rad[24] = {};
    int n = 0;
    for (const Light& l : scene.lights) {
      if (n == 8) break;
      types[n] = l.type == Light::Type::Ambient ? 0 : l.type == Light::Type::Directional ? 1 : 2;
      Vec3 v = l.type == Light::Type::Point ? l.position - origin : l.direction;
      for (int c = 0; c < 3; ++c) {
        vecs[3 * n + c] = float(v[c]);
        rad[3 * n + c] = float(l.radiance[c]);
      }
      ++n;
    }
    p.set("u_num_lights", n);
    glUniform1iv(p.uniformLocation("u_light_type"), 8, types);
    p.setVec3("u_light_vec", vecs, 8);
    p.setVec3("u_light_radiance", rad, 8);
  }

  // Sky and environment from a camera at `origin`; `view_origin` is where the viewing rays start (for the
  // two-sided normal), relative to `origin`.
  // reversed_depth: the zooming-region pass (view_volume.h): the fragment farthest from the camera wins.
  // rays_from: where the viewing rays start (two-sided normals face it); the camera unless given.
  void drawEnvironment(const Mat4& view, const Mat4& proj, const Vec3& origin, bool reversed_depth = false,
                       const Vec3* rays_from = nullptr) const {
    const Mat4 vp = relativeViewProj(proj, view, origin);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    sky_program.use();
    sky_program.set("u_inv_view_proj", toFloat(glm::inverse(vp)));
    sky_program.set("u_background", glm::vec3(scene.render.background));
    sky_program.set("u_far", float(scene.render.far_distance_m));
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(reversed_depth ? GL_GREATER : GL_LESS);
    env_program.use();
    env_program.set("u_view_proj", toFloat(vp));
    env_program.set("u_view_origin", rays_from ? glm::vec3(*rays_from - origin) : glm::vec3(0.0f));
    env_program.set("u_texture", 0);
    setLights(env_program, origin);
    glActiveTexture(GL_TEXTURE0);
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
      const EnvMesh& mesh = scene.meshes[m];
      const DiffuseMaterial& mat = scene.materials[size_t(mesh.material)];
      env_program.set("u_offset", glm::vec3(mesh.anchor - origin));
      env_program.set("u_albedo", glm::vec3(mat.color));
      env_program.set("u_has_texture", mat.texture >= 0 ? 1 : 0);
      if (mat.texture >= 0) glBindTexture(GL_TEXTURE_2D, textures[size_t(mat.texture)].name());
      draw(env_meshes[m]);
    }
  }

  void setElementMaterial(const Program& p, const Element& el, int index) const {
    p.set("u_element_id", float(index + 1));
    p.set("u_metal", el.mirror.metal ? 1 : 0);
    p.set("u_reflectance", glm::vec3(el.mirror.reflectance));
    p.set("u_metal_n", glm::vec3(el.mirror.n));
    p.set("u_metal_k", glm::vec3(el.mirror.k));
  }

  // Whole-element mesh (plain and envmap modes): position relative to the element's origin, normal; for an
  // envmap lens the exact exit direction of each vertex's ray in the first coordinate slot and its Fresnel
  // transmittance (the "refraction vectors" baseline).
  void uploadElementGrid(MeshBuffers& mb, const ElementFrame& f, const Vec3& anchor) {
    std::vector<float> data;
    const bool has_rays = !f.rays.empty();
    for (size_t i = 0; i < f.world_pos.size(); ++i) {
      glm::vec3 p(f.world_pos[i] - anchor), n(f.world_normal[i]);
      const glm::vec3 d = has_rays ? glm::vec3(f.rays[0][i].dir) : glm::vec3(0, 0, 1);
      const glm::vec3 tr = has_rays ? glm::vec3(f.rays[0][i].transmittance) : glm::vec3(1);
      data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, d.x, d.y, d.z, 0, 0, 1, 0, 0, 1, tr.x, tr.y, tr.z});
    }
    std::vector<uint32_t> idx;
    for (const auto& t : f.grid.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
    uploadMesh(mb, data, {3, 3, 3, 3, 3, 3}, idx);
  }

  void uploadPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor) {
    const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
    const size_t channels = pv.st.size();
    std::vector<float> data;
    data.reserve(gp.vertices.size() * 18);
    for (size_t k = 0; k < gp.vertices.size(); ++k) {
      const uint32_t vi = gp.vertices[k];
      glm::vec3 p(f.world_pos[vi] - anchor), n(f.world_normal[vi]);
      data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
      const double q = pv.q[k];
      for (size_t c = 0; c < 3; ++c) {
        const Vec2 st = pv.st[std::min(c, channels - 1)][k];
        data.insert(data.end(), {float(st.x * q), float(st.y * q), float(q)});
      }
      Vec3 tr(1.0);
      for (size_t c = 0; c < 3; ++c) tr[int(c)] = f.rays[std::min(c, channels - 1)][vi].transmittance[int(c)];
      data.insert(data.end(), {float(tr.x), float(tr.y), float(tr.z)});
    }
    std::vector<uint32_t> idx;
    for (const auto& t : gp.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
    uploadMesh(mb, data, {3, 3, 3, 3, 3, 3}, idx);
  }

  Framebuffer& mapTarget(size_t i) {
    if (maps.size() <= i) maps.resize(i + 1);
    if (!maps[i] || maps[i]->width() != options.map_size) {
      maps[i] = std::make_unique<Framebuffer>(options.map_size, options.map_size,
                                              std::vector<ColorFormat>{ColorFormat::RGBA16F, ColorFormat::RGBA32F},
                                              DepthFormat::Depth32F);
      // Colour and seen points filter linearly: seen points are exact within a surface and blend only across
      // depth edges (nearest filtering would quantise every seen point by up to half a texel).
      for (int a = 0; a < 2; ++a) {
        glBindTexture(GL_TEXTURE_2D, maps[i]->colorTexture(a));
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      }
    }
    return *maps[i];
  }

  RasterFrame render(RasterMode mode, FrameCache* cache);
};

Renderer::Renderer(const Scene& scene, const RayScene& rays, RendererOptions options)
    : impl_(std::make_unique<Impl>(scene, rays, std::move(options))) {}
Renderer::~Renderer() = default;

RasterFrame Renderer::render(RasterMode mode, FrameCache* cache) { return impl_->render(mode, cache); }

RasterFrame Renderer::Impl::render(RasterMode mode, FrameCache* cache) {
  const auto frame_start = Clock::now();
  const Observer& ob = scene.observer;
  RasterFrame out;
  out.width = ob.width;
  out.height = ob.height;
  const bool has_lens = std::any_of(scene.elements.begin(), scene.elements.end(),
                                    [](const Element& e) { return e.type == ElementType::Lens; });
  const size_t channels = options.vertex.channels.size();
  const size_t n_el = scene.elements.size();

  // --- CPU stages (pvrr mode) ---
  std::vector<ElementFrame> frames;
  bool skip_first_pass = false;
  if (mode == RasterMode::Pvrr && n_el > 0) {
    frames.resize(n_el);
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
    for (size_t e = 0; e < n_el; ++e)
      reuse[e] = cache && cache->valid && cache->elements.size() == n_el &&
                 same(cache->element_to_eye[e], view * scene.elements[e].local_to_world);
    const bool all_reused = std::all_of(reuse.begin(), reuse.end(), [](bool b) { return b; });
    const bool nothing_moved = all_reused && same(motion, Mat4(1.0)) && !cache->environment_changed;
    const std::string cached = "eye-fixed cache: no element moved relative to the eye";
    auto t0 = Clock::now();
    double refraction_ms = 0, texcoord_ms = 0;
    bool any_texcoords = false;
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
      frames[e] = prepareElement(scene, int(e));
      traceVertexRays(rays, frames[e], ob.eye, options.vertex);
      if (scene.elements[e].type == ElementType::Lens) refraction_ms += frames[e].rays_ms;
    }
    const double cpu_ms = msSince(t0);
    if (all_reused) out.stages.skipped("vertex-rays", cached);
    else out.stages.ran("vertex-rays", cpu_ms - texcoord_ms);
    if (!has_lens) out.stages.skipped("refraction", "no lens in the scene");
    else if (all_reused) out.stages.skipped("refraction", cached);
    else out.stages.ran("refraction", refraction_ms);
    t0 = Clock::now();
    for (size_t e = 0; e < n_el; ++e)
      if (!reuse[e]) fitPatchViews(scene, frames[e], options.vertex);
    if (all_reused) out.stages.skipped("viewpoint-fit", cached);
    else out.stages.ran("viewpoint-fit", msSince(t0));
    if (any_texcoords) out.stages.ran("texture-coordinates", texcoord_ms);
    else out.stages.skipped("texture-coordinates", nothing_moved ? "nothing moved since the last frame"
                                                                 : "computed with the viewpoint fit");
    if (channels > 1) out.stages.ran("colour-channels", 0);
    else out.stages.skipped("colour-channels", has_lens ? "dispersion off: one colour pass" : "no lens: one colour pass");
    skip_first_pass = nothing_moved;
    if (cache) {
      cache->element_to_eye.resize(n_el);
      for (size_t e = 0; e < n_el; ++e) cache->element_to_eye[e] = view * scene.elements[e].local_to_world;
      cache->view = view;
      cache->elements = frames;
      cache->valid = true;
    }
  } else {
    const std::string why = n_el == 0 ? "no mirror or lens in the scene"
                                      : std::string("mode ") + (mode == RasterMode::Raster ? "raster" : "envmap");
    out.stages.skipped("vertex-rays", why);
    out.stages.skipped("refraction", has_lens ? why : "no lens in the scene");
    out.stages.skipped("viewpoint-fit", why);
    out.stages.skipped("texture-coordinates", why);
    out.stages.skipped("colour-channels", why);
  }

  // --- first pass ---
  auto t0 = Clock::now();
  std::vector<size_t> map_index_of_view;
  if (mode == RasterMode::Pvrr && !frames.empty() && skip_first_pass) {
    out.stages.skipped("first-pass", "eye-fixed cache: neither the elements nor the environment moved relative to the eye");
  } else if (mode == RasterMode::Pvrr && !frames.empty()) {
    size_t next = 0;
    for (ElementFrame& f : frames) {
      // In a reversed (zooming) map the rays come from the mirror, not from the viewpoint.
      const Vec3 element_centre = Vec3(scene.elements[size_t(f.element)].local_to_world[3]);
      for (PatchView& pv : f.views) {
        const Framebuffer& t = mapTarget(next++);
        t.bind();
        t.clear({0, 0, 0, 0}, pv.volume.backward ? 0.0f : 1.0f);
        drawEnvironment(pv.volume.view, pv.volume.projection, pv.volume.eye, pv.volume.backward,
                        pv.volume.backward ? &element_centre : nullptr);
      }
    }
    glFinish();
    out.stages.ran("first-pass", msSince(t0));
  } else if (mode == RasterMode::Envmap && n_el > 0) {
    while (cubes.size() < n_el) cubes.push_back(std::make_unique<CubeTarget>());
    for (size_t e = 0; e < n_el; ++e) {
      CubeTarget& c = *cubes[e];
      if (c.size != options.map_size) c.create(options.map_size, {GL_RGBA16F, GL_RGBA32F});
      const Vec3 centre = Vec3(scene.elements[e].local_to_world[3]);
      const double near_m = 1e-3, far_m = 2.0 * (scene.boundsRadius() + glm::length(centre - scene.bounds_min)) + 1.0;
      const Mat4 proj = glm::perspective(kPi / 2, 1.0, near_m, far_m);
      for (int face = 0; face < 6; ++face) {
        c.selectFace(face);
        drawEnvironment(glm::lookAt(centre, centre + kCubeDir[face], kCubeUp[face]), proj, centre);
      }
    }
    glFinish();
    out.stages.ran("first-pass", msSince(t0));
  } else {
    out.stages.skipped("first-pass", n_el == 0 ? "no mirror or lens in the scene" : "mode raster");
  }

  // --- second pass ---
  t0 = Clock::now();
  if (!frame_target || frame_target->width() != ob.width || frame_target->height() != ob.height)
    frame_target = std::make_unique<Framebuffer>(
        ob.width, ob.height, std::vector<ColorFormat>{ColorFormat::RGBA32F, ColorFormat::RGBA32F, ColorFormat::RGBA32F},
        DepthFormat::Depth32F);
  frame_target->bind();
  frame_target->clear({0, 0, 0, 0});
  const double near_m = 1e-3;
  const double far_m = 4.0 * (scene.boundsRadius() + glm::length(ob.eye - 0.5 * (scene.bounds_min + scene.bounds_max))) + 1.0;
  const Mat4 view = ob.view(), proj = ob.projection(near_m, far_m);
  drawEnvironment(view, proj, ob.eye);
  const Mat4 vp = relativeViewProj(proj, view, ob.eye);
  size_t next_map = 0;
  size_t next_mesh = 0;
  auto meshSlot = [&]() -> MeshBuffers& {
    if (element_meshes.size() <= next_mesh) element_meshes.resize(next_mesh + 1);
    return element_meshes[next_mesh++];
  };
  for (size_t e = 0; e < n_el; ++e) {
    const Element& el = scene.elements[e];
    const Vec3 anchor = Vec3(el.local_to_world[3]);
    const bool lens = el.type == ElementType::Lens;
    if (mode == RasterMode::Pvrr) {
      const ElementFrame& f = frames[e];
      const Program& p = lens ? (channels == 3 ? lens3_program : lens_program) : (channels == 3 ? pvrr3_program : pvrr_program);
      p.use();
      p.set("u_view_proj", toFloat(vp));
      p.set("u_offset", glm::vec3(anchor - ob.eye));
      p.set("u_view_origin", glm::vec3(0.0f));
      p.set("u_map", 0);
      p.set("u_seen_map", 1);
      setLights(p, ob.eye);
      setElementMaterial(p, el, int(e));
      for (const PatchView& pv : f.views) {
        const Framebuffer& map = *maps[next_map++];
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, map.colorTexture(0));
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, map.colorTexture(1));
        p.set("u_seen_offset", glm::vec3(pv.volume.eye - ob.eye));
        MeshBuffers& mb = meshSlot();
        uploadPatch(mb, f, pv, anchor);
        frame_target->bind();
        draw(mb);
      }
      glActiveTexture(GL_TEXTURE0);
    } else {
      ElementFrame f = prepareElement(scene, int(e));
      if (lens && mode == RasterMode::Envmap) traceVertexRays(rays, f, ob.eye, VertexStageOptions{});
      const Program& p = mode == RasterMode::Raster ? plain_program : (lens ? lens_envmap_program : envmap_program);
      p.use();
      p.set("u_view_proj", toFloat(vp));
      p.set("u_offset", glm::vec3(anchor - ob.eye));
      p.set("u_view_origin", glm::vec3(0.0f));
      setLights(p, ob.eye);
      setElementMaterial(p, el, int(e));
      if (mode == RasterMode::Envmap) {
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[0]);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[1]);
        glActiveTexture(GL_TEXTURE0);
        p.set("u_cube", 0);
        p.set("u_seen_cube", 1);
        p.set("u_seen_offset", glm::vec3(anchor - ob.eye));
      }
      MeshBuffers& mb = meshSlot();
      uploadElementGrid(mb, f, anchor);
      frame_target->bind();
      draw(mb);
    }
  }
  glFinish();
  checkGlError("rendering a frame");
  out.stages.ran("second-pass", msSince(t0));
  out.elements = std::move(frames);

  if (options.read_back) {
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

#include "pvrr/gl/shadow_pass.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "cad/lens_chord.h"
#include "cad/tessellate.h"
#include "pvrr/gl/environment_pass.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/texture_units.h"
#include "pvrr/gl/stage_notes.h"
#include "pvrr/trace/shadow_rays.h"

namespace pvrr::gl {

namespace {

// The grid of each element's caster mesh: its outline is a polygon of 4 (n - 1) vertices on the exact
// outline, fine against a map texel for the shipped elements.
constexpr int kCasterGrid = 65;
// A point light's maps start this far from it (metres): the depth precision at distance d is about
// d^2 2^-24 / near, 0.1 mm at 5 m.
constexpr double kPointNear_m = 0.02;
// Each point-light face is widened by this many texels beyond 90 degrees on each side, more than the
// filter's reach (1.5 texels of taps plus the bilinear texel).
constexpr double kFaceMarginTexels = 4;
// Caster depth offset (glPolygonOffset): slope factor and units, against acne on surfaces facing the light
// at a grazing angle; the receivers also move off their surface by ShadowPass's normal offset
// (shaders/shadow_lookup.glsl).
constexpr float kOffsetFactor = 2.0f, kOffsetUnits = 4.0f;

// The tangent of each point-light face's half angle.
constexpr double kFaceTanHalf = 1.0 + 2.0 * kFaceMarginTexels / ShadowPass::kMapSize;

// The six axis directions of a point light's maps, in the shader's face order (+x, -x, +y, -y, +z, -z), and
// an up vector for each (shaders/shadow_lookup.glsl pointFace projects with them in closed form).
const Vec3 kFaceAxis[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const Vec3 kFaceUp[6] = {{0, 1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};

}  // namespace

ShadowLayout shadowLayout(const Scene& scene) {
  ShadowLayout out;
  for (const Light& l : scene.lights) {
    const bool casts = l.shadows && l.type != Light::Type::Ambient;
    out.first_layer.push_back(casts ? out.layers : -1);
    if (casts) out.layers += l.type == Light::Type::Point ? 6 : 1;
  }
  out.lenses = std::any_of(scene.elements.begin(), scene.elements.end(),
                           [](const Element& e) { return e.type == ElementType::Lens; });
  return out;
}

std::vector<std::string> shadowDefines(const Scene& scene) {
  const ShadowLayout layout = shadowLayout(scene);
  if (layout.layers == 0) return {};
  std::vector<std::string> d = {"#define SHADOWS", "#define SHADOW_LAYERS " + std::to_string(layout.layers)};
  // GL 4.0's textureGather of a shadow sampler (shaders/shadow_lookup.glsl shadowPcf), in a GLSL 3.30 shader;
  // an older GL gets the same filter from nine filtered lookups (slower on llvmpipe, same picture).
  if (GLAD_GL_VERSION_4_0) {
    d.insert(d.begin(), "#extension GL_ARB_gpu_shader5 : require");
    d.push_back("#define SHADOW_GATHER");
  }
  if (layout.lenses) d.push_back("#define SHADOW_LENSES");
  return d;
}

ShadowPass::ShadowPass(const Scene& scene, const Programs& programs, const EnvironmentPass& environment,
                       int max_texture_units)
    : scene_(scene),
      programs_(programs),
      environment_(environment),
      layout_(shadowLayout(scene)),
      unit_(units::shadowMaps(max_texture_units)) {
  if (!active()) return;
  makeLayers();
  makeTextures();
  programs_.shadowCaster(false);  // built now, so that a compile error comes with the renderer
  if (layout_.lenses) programs_.shadowCaster(true);
  element_meshes_.resize(scene_.elements.size());
  for (size_t e = 0; e < scene_.elements.size(); ++e) {
    const Element& el = scene_.elements[e];
    const cad::Tessellation t =
        cad::tessellateGrid(el.frontSurface(), kCasterGrid, kCasterGrid, el.has_outline ? &el.outline : nullptr);
    std::vector<float> data;
    for (const Vec3& p : t.positions) data.insert(data.end(), {float(p.x), float(p.y), float(p.z)});
    std::vector<uint32_t> idx;
    for (const auto& tri : t.triangles) idx.insert(idx.end(), {tri.x, tri.y, tri.z});
    uploadMesh(element_meshes_[e], data, {3}, idx);
    if (el.type == ElementType::Lens && el.absorbing()) {
      caster_points_.resize(scene_.elements.size());
      caster_indices_.resize(scene_.elements.size());
      chord_casters_.resize(scene_.elements.size());
      caster_points_[e] = t.positions;
      caster_indices_[e] = idx;
      chord_casters_[e].resize(scene_.lights.size());
    }
  }
  checkGlError("making the shadow maps");
}

ShadowPass::~ShadowPass() {
  for (auto& m : element_meshes_) m.release();
  for (auto& per_light : chord_casters_)
    for (ChordCaster& c : per_light) c.mesh.release();
  const unsigned textures[] = {depth_, lens_depth_, lens_t_};
  for (unsigned t : textures)
    if (t) glDeleteTextures(1, &t);
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
}

void ShadowPass::makeLayers() {
  const Vec3 centre = 0.5 * (scene_.bounds_min + scene_.bounds_max);
  const double radius = 1.01 * scene_.boundsRadius() + 1e-3;
  for (const Light& l : scene_.lights) {
    if (!l.shadows || l.type == Light::Type::Ambient) continue;
    if (l.type == Light::Type::Directional) {
      // Orthographic along the light, the bounding sphere wholly inside (distances radius to 3 radius).
      Layer layer;
      layer.origin = centre - 2.0 * radius * l.direction;
      const Vec3 up = std::abs(l.direction.y) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
      layer.view = glm::lookAt(layer.origin, centre, up);
      layer.proj = glm::ortho(-radius, radius, -radius, radius, 0.5 * radius, 3.5 * radius);
      layer.texel_m = 2.0 * radius / kMapSize;
      layer.caustics = l.caustics;
      layer.light = size_t(&l - scene_.lights.data());
      layers_.push_back(layer);
      continue;
    }
    // Point: six faces, each widened by kFaceMarginTexels.
    double far_m = kPointNear_m * 2;
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner((c & 1) ? scene_.bounds_max.x : scene_.bounds_min.x,
                        (c & 2) ? scene_.bounds_max.y : scene_.bounds_min.y,
                        (c & 4) ? scene_.bounds_max.z : scene_.bounds_min.z);
      far_m = std::max(far_m, 1.01 * glm::length(corner - l.position) + 1e-3);
    }
    const double tan_half = kFaceTanHalf;
    for (int f = 0; f < 6; ++f) {
      Layer layer;
      layer.origin = l.position;
      layer.view = glm::lookAt(l.position, l.position + kFaceAxis[f], kFaceUp[f]);
      layer.proj = glm::perspective(2.0 * std::atan(tan_half), 1.0, kPointNear_m, far_m);
      layer.texel_m = 2.0 * tan_half / kMapSize;  // at unit distance along the face's axis
      layer.perspective = true;
      layer.near_m = kPointNear_m;
      layer.far_m = far_m;
      layer.caustics = l.caustics;
      layer.light = size_t(&l - scene_.lights.data());
      layers_.push_back(layer);
    }
  }
}

void ShadowPass::makeTextures() {
  auto makeArray = [&](unsigned& tex, GLenum internal, GLenum format, GLenum type, bool compare) {
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GLint(internal), kMapSize, kMapSize, layout_.layers, 0, format, type, nullptr);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, compare ? GL_LINEAR : GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, compare ? GL_LINEAR : GL_NEAREST);
    // Beyond a map: lit (depth 1 passes every comparison of a point inside the light's depth range), and a
    // transmittance of 1.
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float border[4] = {1, 1, 1, 1};
    glTexParameterfv(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BORDER_COLOR, border);
    if (compare) {
      glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
      glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    }
  };
  makeArray(depth_, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, true);
  if (layout_.lenses) {
    makeArray(lens_depth_, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, true);
    makeArray(lens_t_, GL_RGBA16F, GL_RGBA, GL_FLOAT, false);  // per channel: a tinted lens (lensShadowPassed)
  }
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  glGenFramebuffers(1, &fbo_);
}

std::string ShadowPass::staleReason(const FrameCache* cache) const {
  if (!rendered_) return "first frame";
  if (cache && cache->environment_changed)
    return cache->only_meshes_moved ? meshesMovedReason(scene_, meshesMoved(scene_, rendered_poses_))
                                    : "the environment changed (or a new frame cache)";
  const std::string moved = elementMoved(scene_, rendered_poses_);
  return moved.empty() ? meshesMovedReason(scene_, meshesMoved(scene_, rendered_poses_)) : moved;
}

void ShadowPass::update(FrameStages& stages, const FrameCache* cache) {
  if (!active()) {
    stages.skipped(kShadowMapsStage,
                   "no light casts shadows (every directional and point light has \"shadows\": false)");
    return;
  }
  const std::string why = staleReason(cache);
  if (why.empty()) {
    stages.ran(kShadowMapsStage, 0, 0, "reused: the lights, the environment and the elements stood still");
    return;
  }
  const auto t0 = Clock::now();
  render();
  rendered_poses_ = posesOf(scene_);
  rendered_ = true;
  stages.ran(kShadowMapsStage, msSince(t0), layout_.layers,
             std::to_string(layout_.layers) + (layout_.layers == 1 ? " layer of " : " layers of ") +
                 std::to_string(kMapSize) + " x " + std::to_string(kMapSize) +
                 (layout_.lenses ? ", lens layers beside" : "") + "; drawn: " + why);
}

void ShadowPass::render() {
  GLint previous_fbo = 0, viewport[4];
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous_fbo);
  glGetIntegerv(GL_VIEWPORT, viewport);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_NONE);
  glViewport(0, 0, kMapSize, kMapSize);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(kOffsetFactor, kOffsetUnits);
  const Program& opaque = programs_.shadowCaster(false);
  const Program& lens = programs_.shadowCaster(true);
  for (size_t k = 0; k < layers_.size(); ++k) {
    const Layer& layer = layers_[k];
    const Mat4 vp = relativeViewProj(layer.proj, layer.view, layer.origin);
    // Opaque casters: the environment and the mirrors.
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, 0, 0, 0);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, depth_, 0, GLint(k));
    glDrawBuffer(GL_NONE);
    glClear(GL_DEPTH_BUFFER_BIT);
    environment_.drawCasters(opaque, vp, layer.origin);
    opaque.use();
    opaque.set("u_offset", glm::vec3(0.0f));
    for (size_t e = 0; e < scene_.elements.size(); ++e) {
      if (scene_.elements[e].type != ElementType::Mirror) continue;
      opaque.set("u_view_proj", toFloat(layer.proj * layer.view * scene_.elements[e].local_to_world));
      draw(element_meshes_[e]);
    }
    if (!layout_.lenses) continue;
    // The lenses: the nearest one's depth and transmittance.
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, lens_t_, 0, GLint(k));
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, lens_depth_, 0, GLint(k));
    glDrawBuffer(GL_COLOR_ATTACHMENT0);
    glClearColor(1, 1, 1, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    lens.use();
    lens.set("u_offset", glm::vec3(0.0f));
    for (size_t e = 0; e < scene_.elements.size(); ++e) {
      const Element& el = scene_.elements[e];
      if (el.type != ElementType::Lens) continue;
      lens.set("u_view_proj", toFloat(layer.proj * layer.view * el.local_to_world));
      const bool tinted = el.absorbing() && !layer.caustics;
      lens.set("u_fresnel", layer.caustics ? glm::vec3(0.0f) : glm::vec3(float(lensShadowTransmittance(el))));
      lens.set("u_tinted", int(tinted));
      lens.set("u_absorption_per_m", glm::vec3(el.absorption_per_m));
      draw(tinted ? tintedCaster(e, layer.light) : element_meshes_[e]);
    }
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous_fbo));
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  checkGlError("rendering the shadow maps");
}

const MeshBuffers& ShadowPass::tintedCaster(size_t element, size_t light) {
  const Element& el = scene_.elements[element];
  const Light& l = scene_.lights[light];
  const bool directional = l.type == Light::Type::Directional;
  const Vec3 key = directional ? Mat3(el.world_to_local) * l.direction : Vec3(el.world_to_local * Vec4(l.position, 1.0));
  ChordCaster& c = chord_casters_[element][light];
  if (c.made && c.light_local == key) return c.mesh;
  // Each vertex's chord along the light through it; where none exists (a grazing light), the mean thickness
  // (Element::shadow_path_m), as the reference's shadow rays take it there.
  const std::vector<Vec3>& points = caster_points_[element];
  std::vector<float> data;
  data.reserve(points.size() * 4);
  for (const Vec3& p : points) {
    const Vec3 d = directional ? key : p - key;
    const std::optional<cad::LensChord> chord = cad::chordInside(el.lens, 0, p, d);
    const double length = chord ? chord->length_m : el.shadow_path_m;
    data.insert(data.end(), {float(p.x), float(p.y), float(p.z), float(length)});
  }
  uploadMesh(c.mesh, data, {3, 1}, caster_indices_[element]);
  c.light_local = key;
  c.made = true;
  return c.mesh;
}

void ShadowPass::bind(const Program& p, const Vec3& origin) const {
  if (!active()) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + unit_));
  glBindTexture(GL_TEXTURE_2D_ARRAY, depth_);
  p.set("u_shadow_depth", unit_);
  if (layout_.lenses) {
    glActiveTexture(GLenum(GL_TEXTURE0 + unit_ + 1));
    glBindTexture(GL_TEXTURE_2D_ARRAY, lens_depth_);
    glActiveTexture(GLenum(GL_TEXTURE0 + unit_ + 2));
    glBindTexture(GL_TEXTURE_2D_ARRAY, lens_t_);
    p.set("u_shadow_lens_depth", unit_ + 1);
    p.set("u_shadow_lens_t", unit_ + 2);
  }
  glActiveTexture(GL_TEXTURE0);
  p.set("u_shadow_texel", float(1.0 / kMapSize));
  p.set("u_point_shadow_tan_half", float(kFaceTanHalf));
  // Per light, in the order of setLights' arrays: its first layer (or -1), and for a directional light its
  // matrix from points relative to this pass's origin to its clip space, folded in double; for a point light
  // its maps' near and far distances.
  int dir = 0, point = 0;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    const Light& l = scene_.lights[i];
    const int first = layout_.first_layer[i];
    if (l.type == Light::Type::Directional) {
      const std::string k = "[" + std::to_string(dir++) + "]";
      p.set("u_dir_shadow_layer" + k, float(first));
      if (first < 0) continue;
      const Layer& layer = layers_[size_t(first)];
      p.set("u_dir_shadow_matrix" + k, toFloat(relativeViewProj(layer.proj, layer.view, origin)));
      p.set("u_dir_shadow_texel_m" + k, float(layer.texel_m));
    } else if (l.type == Light::Type::Point) {
      const std::string k = "[" + std::to_string(point++) + "]";
      p.set("u_point_shadow_layer" + k, float(first));
      if (first < 0) continue;
      const Layer& layer = layers_[size_t(first)];
      p.set("u_point_shadow_near_far" + k, glm::vec2(float(layer.near_m), float(layer.far_m)));
    }
  }
}

}  // namespace pvrr::gl

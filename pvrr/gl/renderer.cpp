// The Renderer owns what every pass shares (programs, environment, element meshes, the second pass's target)
// and chooses the work of the frame's mode once (passFor); the passes live beside it:
//   pass_plan.h (pvrr/)  the first passes' plan, map sizes and reuse, without GL
//   pvrr_pass.h          pvrr mode: CPU stages, first-pass maps, element draws with their maps
//   cube_pass.h          envmap and impostor modes: cube maps (with impostor mode's peeled second layers)
//   impostor_maps.h      impostor mode's height and surface maps, and its texture-unit plan
//   environment_pass.h   sky and environment meshes, in every pass
//   shadow_pass.h        the lights' shadow maps, read by the environment's shading in every pass
//   caustic_pass.h       the lights' caustic light maps on planar receivers, read there too
//   element_mesh.h, gl_objects.h, programs.h   element vertices, GL objects, programs built on first use
//   stage_notes.h        the stage names and the texts of their notes
#include "pvrr/gl/renderer.h"

#include <algorithm>

#include "pvrr/base/error.h"
#include "pvrr/gl/caustic_pass.h"
#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/cube_pass.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/pvrr_pass.h"
#include "pvrr/method/cube_quality.h"
#include "pvrr/method/map_limits.h"
#include "pvrr/gl/shadow_pass.h"

namespace pvrr::gl {

namespace {

// Raster mode, and every mode in a scene without an element: the elements as plain surfaces, no CPU stage,
// no first pass.
class RasterPass : public ModePass {
 public:
  explicit RasterPass(const RenderContext& c) : ctx(c) {}
  void prepare(RenderMode mode, FrameStages& stages, FrameCache*) override {
    noteCpuStagesSkipped(stages, ctx.scene, mode);
    noteFirstPassesSkipped(stages, ctx.scene, mode);
  }
  std::string drawElements(RenderMode, const PassCamera& eye, const Framebuffer& target) override {
    const Scene& scene = ctx.scene;
    for (size_t e = 0; e < scene.elements.size(); ++e) {
      target.bind();
      const Element& el = scene.elements[e];
      const Vec3 anchor = Vec3(el.local_to_world[3]);
      const ElementFrame f = prepareElement(scene, int(e), &ctx.grid_cache.get(scene, int(e)));
      MeshBuffers& mesh = ctx.meshes.slot();
      uploadElementGrid(mesh, scene, f, anchor);
      const Program& p = ctx.programs.plain(false);
      p.use();
      p.set("u_view_proj", toFloat(eye.view_proj));
      p.set("u_offset", glm::vec3(anchor - eye.origin));
      p.set("u_view_origin", glm::vec3(0.0f));
      setLights(p, scene, eye.origin);
      setElementMaterial(p, el, int(e));
      p.set("u_dark", 0);
      draw(mesh);
    }
    return "";
  }

 private:
  RenderContext ctx;
};

// Impostor mode: the pixels of each element whose search ended off the distance maps (their seen point's w
// raised by 2, shaders/impostor_search.glsl g_unresolved), into its quality.
void countUnresolvedSearches(RasterFrame& out, const std::vector<float>& seen) {
  std::vector<long> unresolved(out.elements.size(), 0), pixels(out.elements.size(), 0);
  for (size_t i = 0; i < out.element.size(); ++i) {
    const int e = out.element[i];
    if (e < 0 || size_t(e) >= out.elements.size()) continue;
    ++pixels[size_t(e)];
    unresolved[size_t(e)] += seen[4 * i + 3] > 1.5f;
  }
  for (size_t e = 0; e < out.elements.size(); ++e) noteUnresolvedSearches(out.elements[e], unresolved[e], pixels[e]);
}

}  // namespace

struct Renderer::Impl {
  const Scene& scene;
  const RayScene& rays;
  RendererOptions options;
  Programs programs;
  EnvironmentPass environment;
  std::unique_ptr<ShadowPass> shadows;  // made with the first context() (it needs the texture-unit count)
  std::unique_ptr<CausticPass> caustics;  // likewise
  std::unique_ptr<AoFields> ao_fields;  // likewise
  MeshPool meshes;
  ElementGridCache grid_cache;
  int max_texture_size = 0, max_texture_units = 0;
  GlLimits limits;                            // queryGlLimits, with the first context()
  std::vector<double> limits_checked;         // mapLimitsKey of the last frame checkMapLimits passed
  std::unique_ptr<Framebuffer> frame_target;  // the second pass: colour, seen point, surface point
  std::unique_ptr<Framebuffer> default_target;  // the second pass into the window (into_default_framebuffer)
  bool drew_into_default = false;             // the last frame's second pass went into default_target
  // The passes of each mode (made with the renderer; each compiles its programs when a frame first needs them).
  RasterPass raster_pass;
  PvrrPass pvrr_pass;
  CubePass cube_pass;

  Impl(const Scene& s, const RayScene& r, RendererOptions o)
      : scene(s), rays(r), options(std::move(o)), programs(scene, options.seen_points),
        environment(scene, options, programs), raster_pass(context()), pvrr_pass(context()), cube_pass(context()) {}

  RenderContext context() {
    if (!max_texture_size) {
      glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
      glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_texture_units);
      limits = queryGlLimits();
      shadows = std::make_unique<ShadowPass>(scene, programs, environment, max_texture_units);
      environment.setShadows(shadows.get());
      caustics = std::make_unique<CausticPass>(scene, rays, programs, max_texture_units, options.caustic_map_size);
      environment.setCaustics(caustics.get());
      ao_fields = std::make_unique<AoFields>(scene, max_texture_units);
      environment.setAoFields(ao_fields.get());
    }
    return {scene, rays, options, programs, environment, meshes, grid_cache, max_texture_size, max_texture_units};
  }

  // The one place that chooses by mode: raster mode and scenes without elements draw them plain.
  ModePass& passFor(RenderMode mode) {
    if (scene.elements.empty()) return raster_pass;
    switch (mode) {
      case RenderMode::Pvrr: return pvrr_pass;
      case RenderMode::Envmap:
      case RenderMode::Impostor: return cube_pass;
      case RenderMode::Raster:
      case RenderMode::Raytrace: break;  // Renderer::render refuses raytrace
    }
    return raster_pass;
  }

  RasterFrame render(RenderMode mode, FrameCache* cache);
  std::string secondPass(RenderMode mode, ModePass& pass, CullCount* culled);
  void readBack(RasterFrame& out, RenderMode mode) const;
};

Renderer::Renderer(const Scene& scene, const RayScene& rays, RendererOptions options)
    : impl_(std::make_unique<Impl>(scene, rays, std::move(options))) {}
Renderer::~Renderer() = default;

RendererOptions rendererOptionsFor(const Scene& scene) {
  RendererOptions o;
  o.map_size = scene.render.map_size;
  o.map_texels_per_pixel = scene.render.map_texels_per_pixel;
  o.map_reuse_margin_deg = scene.render.map_reuse_margin_deg;
  o.vertex.channels.clear();  // per element: dispersionChannels(scene, e), rgb or spectral as the scene says
  return o;
}

RasterFrame Renderer::render(RenderMode mode, FrameCache* cache) {
  PVRR_CHECK(isRasterMode(mode), "(raytrace is the reference tracer's mode)");
  return impl_->render(mode, cache);
}
void Renderer::setReadBack(bool on) { impl_->options.read_back = on; }
void Renderer::setIntoDefaultFramebuffer(bool on) { impl_->options.into_default_framebuffer = on; }
bool Renderer::drewIntoDefaultFramebuffer() const { return impl_->drew_into_default; }
void Renderer::setCoveredRect(const std::array<int, 4>& rect) { impl_->options.covered_rect = rect; }
std::vector<CausticMap> Renderer::causticMaps() const { return impl_->caustics->readMaps(); }
const CausticPlan& Renderer::causticPlan() const { return impl_->caustics->plan(); }
unsigned Renderer::colorTexture() const {
  return impl_->frame_target && !impl_->drew_into_default ? impl_->frame_target->colorTexture(0) : 0u;
}

RasterFrame Renderer::Impl::render(RenderMode mode, FrameCache* cache) {
  const auto frame_start = Clock::now();
  const Observer& ob = scene.observer;
  RasterFrame out;
  out.width = ob.width;
  out.height = ob.height;
  // Every texture and target of the frame against the GL's limits and memory before anything is drawn, once
  // per change of what the check reads.
  const MapSizeSettings sizes{options.map_size, options.seen_points, options.lens_height_map_size,
                              options.surface_map_size};
  std::vector<double> key = mapLimitsKey(scene, mode, sizes, limits);
  if (key != limits_checked) {
    checkMapLimits(scene, mode, sizes, limits);
    limits_checked = std::move(key);
  }
  meshes.rewind();
  ModePass& pass = passFor(mode);
  // Animated meshes that moved: their buffers rewritten in place (the ray scene is the caller's:
  // RayScene::updateEnvironmentMeshes), and the frame cache started afresh but for the cube maps.
  environment.update();
  if (cache && cache->mesh_motion.empty()) {
    cache->mesh_motion = scene.mesh_motion;  // its first frame
  } else if (cache && cache->mesh_motion != scene.mesh_motion) {
    const bool caller_changed = cache->environment_changed;
    *cache = FrameCache{};
    cache->mesh_motion = scene.mesh_motion;
    cache->only_meshes_moved = !caller_changed;
  }
  shadows->update(out.stages, cache);  // before the first passes, whose environment reads the maps too
  caustics->update(out.stages);
  ao_fields->note(out.stages);
  // The CPU stages and the first passes (and the nested passes of elements seen in other elements' maps).
  pass.prepare(mode, out.stages, cache);
  const auto t0 = Clock::now();
  CullCount culled;
  const std::string layer_note = secondPass(mode, pass, &culled);
  noteSecondPass(out.stages, msSince(t0), cullNote(culled, options.cull_back_faces), layer_note, options.seen_points);
  out.elements = pass.takeElements();
  readBack(out, mode);
  out.frame_ms = msSince(frame_start);
  if (cache) cache->only_meshes_moved = false;
  return out;
}

// The second pass: the elements, then the environment behind them; returns the elements' note.
std::string Renderer::Impl::secondPass(RenderMode mode, ModePass& pass, CullCount* culled) {
  const Observer& ob = scene.observer;
  // A picture-only frame goes into 16 bits a channel (RendererOptions::seen_points), unless an element is
  // drawn in several additive draws (more than three channels): their partial sums can be negative or above
  // 1 (spectral weights), and a normalised target would clamp each before the sum.
  const ColorFormat colour = options.seen_points || pass.additiveDraws() ? ColorFormat::RGBA32F : ColorFormat::RGBA16;
  // A window's frame straight into its back buffer (RendererOptions::into_default_framebuffer).
  drew_into_default = options.into_default_framebuffer && !options.seen_points && !options.read_back &&
                      !pass.additiveDraws();
  if (drew_into_default) {
    if (!default_target || default_target->width() != ob.width || default_target->height() != ob.height)
      default_target = std::make_unique<Framebuffer>(Framebuffer::defaultOfCurrentContext(ob.width, ob.height));
  } else if (!frame_target || frame_target->width() != ob.width || frame_target->height() != ob.height ||
             frame_target->colorFormat(0) != colour) {
    frame_target = std::make_unique<Framebuffer>(
        ob.width, ob.height,
        options.seen_points ? std::vector<ColorFormat>{colour, ColorFormat::RGBA32F, ColorFormat::RGBA32F}
                            : std::vector<ColorFormat>{colour},
        DepthFormat::Depth32F);
  }
  const Framebuffer& target = drew_into_default ? *default_target : *frame_target;
  if (drew_into_default) glEnable(GL_FRAMEBUFFER_SRGB);
  target.clearDepth();  // no colour clear: the sky covers every pixel nothing else does
  const std::array<int, 4>& covered = options.covered_rect;
  if (drew_into_default && covered[2] > covered[0] && covered[3] > covered[1]) {
    // What the caller draws over: depth at the near plane, nothing passes there (RendererOptions::covered_rect).
    const float near_depth = 0.0f;
    glDepthMask(GL_TRUE);
    glEnable(GL_SCISSOR_TEST);
    glScissor(covered[0], covered[1], covered[2] - covered[0], covered[3] - covered[1]);
    glClearBufferfv(GL_DEPTH, 0, &near_depth);
    glDisable(GL_SCISSOR_TEST);
  }
  // The elements come first: the depth state must not depend on what an earlier pass (or none) left.
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  const double near_m = 1e-3;
  const double far_m = 4.0 * (scene.boundsRadius() + glm::length(ob.eye - 0.5 * (scene.bounds_min + scene.bounds_max))) + 1.0;
  const Mat4 view = ob.view(), proj = ob.projection(near_m, far_m);
  PassCamera eye;
  eye.origin = ob.eye;
  eye.view_proj = relativeViewProj(proj, view, ob.eye);
  const std::string note = pass.drawElements(mode, eye, target);
  // The environment after the elements: behind a lens or mirror it fails the early depth test, unshaded.
  target.bind();
  *culled = environment.draw(view, proj, ob.eye);
  if (drew_into_default) glDisable(GL_FRAMEBUFFER_SRGB);
  glFinish();
  checkGlError("rendering a frame");
  return pass.finishedNote(note);
}

void Renderer::Impl::readBack(RasterFrame& out, RenderMode mode) const {
  const Observer& ob = scene.observer;
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
    if (mode == RenderMode::Impostor) countUnresolvedSearches(out, seen);
  }
}

}  // namespace pvrr::gl

#include "pvrr/gl/pvrr_pass.h"

#include <algorithm>
#include <atomic>

#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/impostor_maps.h"
#include "pvrr/method/local_split.h"
#include "pvrr/method/map_footprint.h"
#include "pvrr/method/refine_plan.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr::gl {

namespace {

// The texture units of an element's pvrr draw: its patch's map, the map's seen points, and the G and B planes of
// an RGB map (R on kMapUnit). A refined mirror (never an RGB element: pvrr_refine.glsl) reads its surface maps
// and its map's depth on impostor_maps.h's units; a refined lens its map's depth there too, and its refractor
// height maps after it (pvrr_refine.cpp's kRefineLensUnit: the planes take kPlaneUnitG and the next).
constexpr int kMapUnit = 0, kSeenMapUnit = 1, kPlaneUnitG = 2;

// A serial number for every first pass rendered in the process (FrameCache::maps_serial).
uint64_t nextFirstPassSerial() {
  static std::atomic<uint64_t> serial{0};
  return ++serial;
}

// Whether cached rays were traced for these channels (wavelengths and weights, not just their count).
bool sameChannels(const std::vector<ChannelSpec>& a, const std::vector<ChannelSpec>& b) {
  if (a.size() != b.size()) return false;
  for (size_t c = 0; c < a.size(); ++c)
    if (a[c].wavelength_nm != b[c].wavelength_nm || channelWeight(a, c) != channelWeight(b, c)) return false;
  return true;
}

// A refined lens's surfaces that are spheres or planes (bit 0 the front, bit 1 the back), met in closed form in
// the shader (SPHERE_FRONT, SPHERE_BACK); *u: their curvatures and vertex heights (u_spheres). Bit 2: its
// outline is an ellipse or a circle (OUTLINE_ELLIPSE), *ellipse its centre and inverse half axes (u_ellipse).
int refineSpheres(const Element& el, glm::vec4* u, glm::vec4* ellipse) {
  int bits = 0;
  double c = 0;
  if (el.lens.front->sphereCurvature(&c)) {
    bits |= 1;
    (*u)[0] = float(c);
    (*u)[1] = float(el.lens.front->zVertex());
  }
  if (el.lens.back->sphereCurvature(&c)) {
    bits |= 2;
    (*u)[2] = float(c);
    (*u)[3] = float(el.lens.back->zVertex());
  }
  const cad::Outline& o = el.lens.outline;
  if (o.shape() == cad::Outline::Shape::Ellipse || o.shape() == cad::Outline::Shape::Circle) {
    bits |= 4;
    const double a = 0.5 * o.width(), b = o.shape() == cad::Outline::Shape::Circle ? a : 0.5 * o.height();
    *ellipse = glm::vec4(float(o.centre().x), float(o.centre().y), float(1.0 / a), float(1.0 / b));
  }
  return bits;
}

}  // namespace

PvrrPass::~PvrrPass() {
  if (refine_counters) glDeleteBuffers(1, &refine_counters);
  if (refine_sampler) glDeleteSamplers(1, &refine_sampler);
  if (!refine_queries.empty()) glDeleteQueries(GLsizei(refine_queries.size()), refine_queries.data());
  for (auto& views : refine_split)
    for (RefineSplitMesh& m : views) m.quadratic.release(), m.searched.release();
  if (mask_vbo) glDeleteBuffers(1, &mask_vbo);
  if (mask_vao) glDeleteVertexArrays(1, &mask_vao);
}

VertexStageOptions PvrrPass::optionsFor(size_t e) const {
  VertexStageOptions o = ctx.options.vertex;
  if (o.channels.empty()) o.channels = dispersionChannels(ctx.scene, int(e));
  // The scene's choice, unless it leaves it to the renderer's options (auto).
  if (ctx.scene.render.viewpoint_solver != ViewpointSolver::kAuto)
    o.viewpoint.solver = ctx.scene.render.viewpoint_solver;
  // As seen from the eye: the tracer's whole budget (none for a lens drawn dark at the depth limit).
  o.tir_trace_depth = elementInterfaces(ctx.scene.elements[e]) > ctx.scene.render.max_depth ? 0 : ctx.scene.render.max_depth;
  return o;
}

void PvrrPass::prepare(RenderMode, FrameStages& stages, FrameCache* cache) {
  const bool nothing_moved = cpuStages(stages, cache);
  refine_nothing_moved = nothing_moved;
  // The quadratic split's nodes follow the eye, the element and the scene: kept only while nothing moved.
  if (!nothing_moved)
    for (RefineMidpoints& m : refine_mids) m.nodes_fresh = false;
  prepareRefinement(cache && cache->valid);
  firstPass(stages, cache, nothing_moved, cache && cache->valid);
  // The cache takes this frame whole, once its maps are drawn: the poses, and the elements with the volumes
  // and texture coordinates of the maps now held.
  if (cache) {
    const Scene& scene = ctx.scene;
    const Mat4 view = scene.observer.view();
    const size_t n_el = scene.elements.size();
    cache->element_to_eye.resize(n_el);
    for (size_t e = 0; e < n_el; ++e) cache->element_to_eye[e] = view * scene.elements[e].local_to_world;
    cache->view = view;
    cache->projection = scene.observer.visibilityProjection();
    cache->elements = frames;
    cache->frame_serial = first_pass_serial;
    cache->valid = true;
  }
}

bool PvrrPass::cpuStages(FrameStages& stages, FrameCache* cache) {
  const Scene& scene = ctx.scene;
  const Observer& ob = scene.observer;
  const size_t n_el = scene.elements.size();
  frames.assign(n_el, ElementFrame{});
  opts.clear();
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
  PvrrCpuStages s;
  s.all_reused = std::all_of(reuse.begin(), reuse.end(), [](bool b) { return b; });
  // Nothing moved, and the maps this renderer holds are the ones the cached frame was drawn with.
  s.nothing_moved = s.all_reused && same(motion, Mat4(1.0)) && !cache->environment_changed &&
                    cache->frame_serial == first_pass_serial;
  s.has_lens = std::any_of(scene.elements.begin(), scene.elements.end(),
                           [](const Element& e) { return e.type == ElementType::Lens; });
  auto t0 = Clock::now();
  for (size_t e = 0; e < n_el; ++e) {
    if (reuse[e]) {
      frames[e] = cache->elements[e];
      if (!s.nothing_moved) {
        moveRigidly(frames[e], motion);
        updateTextureCoordinates(ctx.rays, frames[e]);
        s.texcoord_ms += frames[e].rays_ms;
        s.any_texcoords = true;
      }
      continue;
    }
    frames[e] = prepareElement(scene, int(e), &ctx.grid_cache.get(scene, int(e)));
    traceVertexRays(ctx.rays, frames[e], ob.eye, opts[e]);
    if (scene.elements[e].type == ElementType::Lens) s.refraction_ms += frames[e].rays_ms;
    else s.mirror_rays += frames[e].rays.size() * frames[e].world_pos.size(), s.beside += size_t(frames[e].rays_beside);
  }
  s.rays_ms = msSince(t0) - s.texcoord_ms;
  t0 = Clock::now();
  for (size_t e = 0; e < n_el; ++e) {
    if (!reuse[e]) {
      fitPatchViews(scene, frames[e], opts[e]);
      refineElement(e);
    }
    // Every frame, reused or not: what lies along the rays may have moved. A mirror's outgoing ray has
    // spent one event of the budget; a lens's has spent its interfaces.
    const int spent = scene.elements[e].type == ElementType::Lens ? elementInterfaces(scene.elements[e]) : 1;
    applyTracedFallback(ctx.rays, frames[e], opts[e].tir_trace_depth - spent);
  }
  s.fit_ms = msSince(t0);
  notePvrrCpuStages(stages, s, frames);
  return s.nothing_moved;
}

// Adaptive refinement (issue 26 item 2): an element whose triangles span too much curvature for their rays
// to interpolate well is refined, traced and fitted again; the grid cache keeps the refinement for the
// following frames. The whole grid first (refinedGridSize); then, with VertexStageOptions::refine_locally, the
// base quads of that grid whose maps still err, each to its own level (chooseLocalSplitByMapError), within the
// same vertex budget.
void PvrrPass::refineElement(size_t e) {
  ElementFrame& f = frames[e];
  const Element& el = ctx.scene.elements[e];
  bool again = false;
  std::string budget, broad;
  const int max_vertices = opts[e].refine_max_vertices;
  if (max_vertices > 0 && !f.grid.locallyRefined()) {
    const std::array<int, 2> size = refinedGridSize(f, max_vertices);
    if (size[0] != f.grid.grid_u || size[1] != f.grid.grid_v) {
      ctx.grid_cache.refine(ctx.scene, int(e), size[0], size[1]);
      if (opts[e].refine_locally) {  // the local split measures the refined grid's maps
        f = prepareElement(ctx.scene, int(e), &ctx.grid_cache.get(ctx.scene, int(e)));
        traceVertexRays(ctx.rays, f, ctx.scene.observer.eye, opts[e]);
        fitPatchViews(ctx.scene, f, opts[e]);
      } else {
        again = true;
      }
    }
  }
  if (max_vertices > 0 && opts[e].refine_locally) {
    // A lens whose map errs broadly is split on that alone (kBroadLensMapErrorArcmin); a mirror never.
    const double broad_limit = el.type == ElementType::Lens ? kBroadLensMapErrorArcmin : kInf;
    const LocalSplit ls = chooseLocalSplitByMapError(ctx.rays, f, max_vertices, {}, 0.9,
                                                     ctx.grid_cache.refined(int(e))[0] > 0, broad_limit);
    if (ls.changed) {
      ctx.grid_cache.refineLocally(ctx.scene, int(e), ls.levels);
      again = true;
    }
    if (ls.budget_limited) budget = " (vertex budget " + std::to_string(max_vertices) + " reached)";
    if (ls.changed && ls.broad_map_error)
      broad = " (no spread limit was reached, but a sample of its quads erred by " + fmt("%.1f", ls.sampled_median_arcmin) +
              "' median, over the " + fmt("%.1f", broad_limit) + "' limit)";
  }
  if (again) {
    f = prepareElement(ctx.scene, int(e), &ctx.grid_cache.get(ctx.scene, int(e)));
    traceVertexRays(ctx.rays, f, ctx.scene.observer.eye, opts[e]);
    fitPatchViews(ctx.scene, f, opts[e]);
  }
  if (f.grid.locallyRefined()) {
    int split = 0, level = 0;
    for (uint8_t l : f.grid.quad_levels) split += l > 0, level = std::max(level, int(l));
    f.quality.action = std::to_string(split) + " of the " + std::to_string(f.grid.quad_levels.size()) + " quads of the " +
                       std::to_string(f.grid.grid_u) + "x" + std::to_string(f.grid.grid_v) +
                       " grid split locally to level " + std::to_string(level) + ", " +
                       std::to_string(f.grid.vertexCount()) + " vertices, where the map's interpolation erred" +
                       broad + budget + "; " + f.quality.action;
  }
  if (ctx.grid_cache.refined(int(e))[0] > 0) {
    f.quality.action = "grid refined from " + std::to_string(el.tess_u) + "x" + std::to_string(el.tess_v) + " to " +
                       std::to_string(f.grid.grid_u) + "x" + std::to_string(f.grid.grid_v) +
                       " where its triangles spanned too wide a spread of normals or of traced directions; " + f.quality.action;
  }
}

void PvrrPass::firstPass(FrameStages& stages, FrameCache* cache, bool skip_first_pass, bool continuing) {
  const auto t0 = Clock::now();
  // Map reuse (PassPlanOptions::map_reuse_margin_deg): a frame that follows another draws from the maps of
  // an earlier one while its views stay inside them; otherwise its maps are drawn widened by the margin.
  const bool reuse_on = ctx.options.map_reuse_margin_deg > 0 && continuing;
  PvrrFirstPass s;
  s.reuse_on = reuse_on;
  if (reuse_on && !skip_first_pass && !cache->environment_changed &&
      reuseMaps(ctx.scene, frames, *cache, ctx.options, first_pass_serial, planesSlots(), &s.reuse_note)) {
    skip_first_pass = true;
    ++cache->maps_age;
  } else if (reuse_on && skip_first_pass && !cache->maps.empty()) {
    ++cache->maps_age;  // nothing moved: the same maps, one frame older
  }
  // Maps are widened for reuse unless the last first pass could not be kept (nested passes, dark elements)
  // or no view can be (reversed maps are never widened nor reused).
  s.any_forward = std::any_of(frames.begin(), frames.end(), [](const ElementFrame& f) {
    return std::any_of(f.views.begin(), f.views.end(), [](const PatchView& v) { return !v.volume.backward; });
  });
  s.widen = reuse_on && !cache->last_plan_nested && s.any_forward;
  if (skip_first_pass) {
    notePvrrFirstPassSkipped(stages, s.reuse_note);
    return;
  }
  std::vector<std::array<int, 2>> widened;  // per top-level slot: texture size, rendered side
  if (s.widen) widened = widenMaps(ctx.scene, frames, ctx.options, ctx.max_texture_size);
  plan = planPasses(ctx.scene, ctx.rays, frames, opts, ctx.options, s.widen ? &widened : nullptr);
  map_side.assign(plan.passes.size(), 0);
  for (const MapPass& mp : plan.passes) map_side[mp.slot] = mp.side;
  s.plan_ms = msSince(t0);
  const auto t1 = Clock::now();
  // The maps change from here: any cache's record of them is void, even if a pass fails.
  first_pass_serial = nextFirstPassSerial();
  if (cache) cache->maps.clear();
  s.culled = renderPasses(s.widen ? widened.size() : 0, &s.unread, &s.texels);
  glFinish();
  if (cache) {
    cache->last_plan_nested = plan.nested() > 0 || plan.dark > 0;
    if (s.widen && !cache->last_plan_nested) {
      for (size_t i = 0; i < widened.size(); ++i) {
        const MapPass& mp = plan.passes[i];
        cache->maps.push_back({mp.owner->element, mp.view, mp.owner->views[mp.view].volume, mp.side, mp.visible});
      }
      cache->maps_serial = first_pass_serial;
      cache->maps_age = 0;
    }
  }
  s.ms = msSince(t1);
  notePvrrFirstPass(stages, ctx.scene, ctx.options, plan, planesSlots(), s);
}

std::vector<bool> PvrrPass::planesSlots() const {
  std::vector<bool> out(maps.size(), false);
  for (size_t i = 0; i < maps.size(); ++i) out[i] = maps[i] && maps[i]->colorFormat(0) == ColorFormat::R32F;
  return out;
}

// The map texture of slot i: size x size, colour RGBA32F (planes: three R32F planes), then the seen points
// (RGBA32F) when they are wanted.
Framebuffer& PvrrPass::mapTarget(size_t i, int size, bool planes) {
  if (maps.size() <= i) maps.resize(i + 1);
  const bool is_planes = maps[i] && maps[i]->colorFormat(0) == ColorFormat::R32F;
  if (!maps[i] || maps[i]->width() != size || is_planes != planes) {
    // RGBA32F colour: llvmpipe filters it faster than RGBA16F (docs/method.md "Measurements behind the
    // design"), and it keeps values above 1 exactly. Planes: one float a read.
    std::vector<ColorFormat> formats = planes ? std::vector<ColorFormat>{ColorFormat::R32F, ColorFormat::R32F, ColorFormat::R32F}
                                              : std::vector<ColorFormat>{ColorFormat::RGBA32F};
    if (ctx.options.seen_points) formats.push_back(ColorFormat::RGBA32F);
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

// One patch of a PVRR element for one set of (up to) three channels, `set` = 0, 1, ...: the projective
// texture coordinates of channels 3 set + j, their weights (colour weight * transmittance, 0 for the
// padding of the last set), and the coordinates of channel `seen_channel` for the seen point.
void PvrrPass::uploadPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor, size_t set,
                           size_t seen_channel) const {
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
      // A patch drawn traced reads no map: its vertices' traced colours below are the whole picture.
      const Vec3 w =
          pv.draw_traced ? Vec3(0.0) : weight[j] * f.rays[std::min(3 * set + j, channels - 1)][vi].transmittance;
      data.insert(data.end(), {float(w.x), float(w.y), float(w.z)});
    }
    const Vec2 st = pv.st[seen_channel][k];
    data.insert(data.end(), {float(st.x * q), float(st.y * q), float(q)});
    // Totally reflected channels: their map weight is 0 and the tracer's colour takes its place, added in
    // the draw of their set; the seen point follows the seen channel (first draw).
    Vec3 traced(0.0);
    for (size_t j = 0; j < 3 && 3 * set + j < channels; ++j) {
      const VertexRay& r = f.rays[3 * set + j][vi];
      if (usesTraced(pv, r)) traced += weight[j] * r.traced_color;
    }
    const VertexRay& seen_ray = f.rays[seen_channel][vi];
    const bool seen_traced = set == 0 && usesTraced(pv, seen_ray);
    const glm::vec3 ts = seen_traced ? glm::vec3(seen_ray.traced_seen - anchor) : glm::vec3(0.0f);
    data.insert(data.end(), {float(traced.x), float(traced.y), float(traced.z), seen_traced ? 1.0f : 0.0f, ts.x, ts.y, ts.z});
  }
  std::vector<uint32_t> idx;
  for (const auto& t : gp.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
  uploadMesh(mb, data, kElementLayout, idx);
}

// Draws one element with its PVRR maps into the bound target, as seen by `cam`. More than three channels
// (spectral): one draw per set of three, added into colour attachment 0 only (same vertices, depth test
// LEQUAL); the seen point and the surface attachments come from the first draw.
void PvrrPass::drawPvrrElement(const ElementFrame& f, size_t first_slot, const PassCamera& cam, int seen_channel) {
  const Element& el = ctx.scene.elements[size_t(f.element)];
  const Vec3 anchor = Vec3(el.local_to_world[3]);
  const bool lens = el.type == ElementType::Lens;
  const size_t channels = f.rays.size();
  // RGB dispersion: its maps are planes, read one component per channel. Drawn into a planes map (only RGB
  // scenes have them: never more than three channels), the planes variant.
  const bool rgb = rgbLens(el, f);
  const bool refined = refine_skip.size() > size_t(f.element) && refine_skip[size_t(f.element)].empty();
  glm::vec4 spheres_uniform(0.0f), ellipse_uniform(0.0f);
  const int spheres = refined && lens ? refineSpheres(el, &spheres_uniform, &ellipse_uniform) : 0;
  const Program& p = ctx.programs.pvrr(lens, channels, rgb, cam.planes, refined ? ctx.scene.render.refine : 0, spheres,
                                       refined && refine_counting && refine_count_frame);
  // A refined mirror in the second pass: its triangles that need no search drawn first by the quadratic
  // program (uploadQuadraticPatch), the others by the search.
  const bool split = refined && !lens && refine_counting;
  const Program* quadratic = split ? &ctx.programs.pvrr(false, 1, false, cam.planes, Programs::kRefineQuadratic) : nullptr;
  for (const Program* q : {quadratic, &p}) {
    if (!q) continue;
    q->use();
    q->set("u_view_proj", toFloat(cam.view_proj));
    q->set("u_offset", glm::vec3(anchor - cam.origin));
    q->set("u_view_origin", glm::vec3(cam.rays_from));
    q->set("u_map", kMapUnit);
    q->set("u_seen_map", kSeenMapUnit);
    q->set("u_map_g", kPlaneUnitG);
    q->set("u_map_b", kPlaneUnitG + 1);
    setLights(*q, ctx.scene, cam.origin);
    setElementMaterial(*q, el, f.element);
    q->set("u_additive", 0);
  }
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
  if (refined) setRefinement(p, f, seen_c);
  if (spheres & 3) p.set("u_spheres", spheres_uniform);
  if (spheres & 4) p.set("u_ellipse", ellipse_uniform);
  for (size_t v = 0; v < f.views.size(); ++v) {
    const PatchView& pv = f.views[v];
    const Framebuffer& map = *maps[first_slot + v];
    const int planes = map.colorFormat(0) == ColorFormat::R32F ? 3 : 1;  // colour attachments before the seen points
    if ((planes == 3) != rgb) throw Error("renderer: map slot " + std::to_string(first_slot + v) + " of " + el.name + " is " +
                                          (planes == 3 ? "in planes" : "RGBA") + " but the element's channels are " +
                                          (rgb ? "RGB" : "not RGB") + " (internal error)");
    if (cam.planes && sets > 1) throw Error("renderer: additive channel draws into a planes map (internal error)");
    glActiveTexture(GLenum(GL_TEXTURE0 + kMapUnit));
    glBindTexture(GL_TEXTURE_2D, map.colorTexture(0));
    if (planes == 3) {
      glActiveTexture(GLenum(GL_TEXTURE0 + kPlaneUnitG));
      glBindTexture(GL_TEXTURE_2D, map.colorTexture(1));
      glActiveTexture(GLenum(GL_TEXTURE0 + kPlaneUnitG + 1));
      glBindTexture(GL_TEXTURE_2D, map.colorTexture(2));
    }
    glActiveTexture(GLenum(GL_TEXTURE0 + kSeenMapUnit));
    if (ctx.options.seen_points) glBindTexture(GL_TEXTURE_2D, map.colorTexture(planes));
    p.set("u_seen_offset", glm::vec3(pv.volume.eye - cam.origin));
    // The map fills the lower-left mapTexels() of its texture: (s, t) in [0, 1]^2 of the volume scale to
    // that region, clamped half a texel inside it (as GL_CLAMP_TO_EDGE does at the texture's own edge).
    const std::array<int, 2> region = mapTexels(pv.volume, map_side[first_slot + v]);
    const glm::vec2 texels{float(region[0]), float(region[1])}, size{float(map.width()), float(map.height())};
    p.set("u_st_scale", texels / size);
    p.set("u_st_max", (texels - 0.5f) / size);
    if (refined) setRefinementView(p, f.element, pv, map, map_side[first_slot + v]);
    if (split && refineViewSkipReason(pv).empty()) {
      drawRefinedSplit(p, *quadratic, f, v, anchor, glm::vec3(pv.volume.eye - cam.origin), texels / size,
                       (texels - 0.5f) / size);
      unsetRefinement();
      continue;
    }
    for (size_t set = 0; set < sets; ++set) {
      MeshBuffers& mb = ctx.meshes.slot();
      if (refined && !lens)
        uploadRefinedPatch(mb, f, pv, anchor);
      else
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
    if (refined) unsetRefinement();
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
void PvrrPass::drawDarkElement(const ElementFrame& f, const PassCamera& cam) {
  const Element& el = ctx.scene.elements[size_t(f.element)];
  const Vec3 anchor = Vec3(el.local_to_world[3]);
  const Program& plain = ctx.programs.plain(cam.planes);
  plain.use();
  plain.set("u_view_proj", toFloat(cam.view_proj));
  plain.set("u_offset", glm::vec3(anchor - cam.origin));
  plain.set("u_view_origin", glm::vec3(cam.rays_from));
  plain.set("u_dark", 1);
  setLights(plain, ctx.scene, cam.origin);
  setElementMaterial(plain, el, f.element);
  MeshBuffers& mb = ctx.meshes.slot();
  uploadElementGrid(mb, ctx.scene, f, anchor);
  draw(mb);
}

// Sets the depth of the texels of map pass mp's region (bound, depth cleared) that its element cannot fetch
// (MapFootprint of its patch's triangles at their texture coordinates, in every channel) to what no
// fragment of the pass passes: 0 with GL_LESS, 1 with a reversed pass's GL_GREATER. Returns their count.
int64_t PvrrPass::closeUnreadTexels(const MapPass& mp, const std::array<int, 2>& region) {
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
  const Program& mask_program = ctx.programs.mask();
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
CullCount PvrrPass::renderPasses(size_t whole_slots, int64_t* skipped, int64_t* texels) {
  CullCount count;
  *skipped = *texels = 0;
  for (size_t i = plan.passes.size(); i-- > 0;) {
    const MapPass& mp = plan.passes[i];
    const PatchView& pv = mp.owner->views[mp.view];
    const bool planes = rgbLens(ctx.scene.elements[size_t(mp.owner->element)], *mp.owner);
    const Framebuffer& t = mapTarget(mp.slot, mp.size, planes);
    if (!mp.visible) continue;
    // No colour clear: the sky covers every texel nothing else does (EnvironmentPass::draw).
    const std::array<int, 2> region = mapTexels(pv.volume, mp.side);
    t.bindRegionClearDepth(region[0], region[1], pv.volume.backward ? 0.0f : 1.0f);
    *texels += int64_t(region[0]) * region[1];
    if (ctx.options.skip_unread_texels && mp.slot >= whole_slots) *skipped += closeUnreadTexels(mp, region);
    // In a reversed (zooming) map the rays come from the mirror, not from the viewpoint.
    const Vec3 element_centre = Vec3(ctx.scene.elements[size_t(mp.owner->element)].local_to_world[3]);
    // A patch whose near plane could not clip the mirror: what lies behind the mirror is clipped at its plane.
    const Vec4* clip = pv.volume.clip_plane ? &*pv.volume.clip_plane : nullptr;
    count.add(ctx.environment.draw(pv.volume.view, pv.volume.projection, pv.volume.eye, pv.volume.backward,
                                   pv.volume.backward ? &element_centre : nullptr, planes, false, false, clip));
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

bool PvrrPass::additiveDraws() const {
  return std::any_of(frames.begin(), frames.end(), [](const ElementFrame& f) { return f.rays.size() > 3; });
}

std::string PvrrPass::drawElements(RenderMode, const PassCamera& eye, const Framebuffer& target) {
  size_t slot = 0;  // the map slot of frames[e].views[0]
  refine_counting = true;
  refine_count_frame = refineCountThisFrame(eye, target);
  for (size_t e = 0; e < frames.size(); ++e) {
    const ElementFrame& f = frames[e];
    target.bind();
    const bool refined = refine_count_frame && refine_skip.size() > e && refine_skip[e].empty();
    if (refined) glBeginQuery(GL_SAMPLES_PASSED, refine_queries[e]);
    if (beyondDepth(ctx.scene, f)) drawDarkElement(f, eye);
    else drawPvrrElement(f, slot, eye, ctx.options.seen_channel);
    if (refined) glEndQuery(GL_SAMPLES_PASSED);
    slot += f.views.size();
  }
  refine_counting = false;
  return "";
}

}  // namespace pvrr::gl

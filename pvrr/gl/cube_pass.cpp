#include "pvrr/gl/cube_pass.h"

#include <algorithm>

#include "pvrr/base/format.h"
#include "pvrr/gl/gl.h"
#include "pvrr/method/cube_quality.h"

namespace pvrr::gl {

namespace {
// Cube-map faces in GL order (+X, -X, +Y, -Y, +Z, -Z): view direction and up vector.
const Vec3 kCubeDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const Vec3 kCubeUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
}  // namespace

bool CubePass::inCubes(size_t m) const {
  return follow > 0 && (ctx.scene.elements[m].type == ElementType::Mirror || lens_in_cubes);
}

CubePass::CubeKey CubePass::keyNow(size_t formats) const {
  CubeKey k;
  k.mode = mode;
  k.map_size = ctx.options.map_size;
  k.layers = layers;
  k.follow = follow;
  k.formats = formats;
  k.lens_in_cubes = lens_in_cubes;
  for (const Element& el : ctx.scene.elements) k.poses.push_back(el.local_to_world);
  return k;
}

std::string CubePass::staleReason(const FrameCache* cache, const CubeKey& k) const {
  if (!cache) return "no frame cache (a single frame)";
  if (cache->environment_changed) return "the environment changed (or a new frame cache)";
  if (!drawn_key) return "first frame";
  const CubeKey& d = *drawn_key;
  if (d.mode != k.mode || d.map_size != k.map_size || d.layers != k.layers || d.follow != k.follow ||
      d.formats != k.formats || d.lens_in_cubes != k.lens_in_cubes || d.poses.size() != k.poses.size())
    return "the mode or the map settings changed";
  for (size_t e = 0; e < k.poses.size(); ++e)
    if (d.poses[e] != k.poses[e])
      return "element \"" + ctx.scene.elements[e].name + "\" moved" +
             (ctx.scene.elements[e].attached_to_observer ? " (attached to the observer)" : "");
  return "";
}

void CubePass::prepare(RenderMode frame_mode, FrameStages& stages, FrameCache* cache) {
  const Scene& scene = ctx.scene;
  mode = frame_mode;
  noteCpuStagesSkipped(stages, scene, mode);
  const auto t0 = Clock::now();
  const size_t n_el = scene.elements.size();
  while (cubes.size() < n_el) cubes.push_back(std::make_unique<CubeTarget>());
  layers = maps.impostorLayers(mode);
  while (layers > 1 && cubes1.size() < n_el) cubes1.push_back(std::make_unique<CubeTarget>());
  if (layers == 1) cubes1.clear();  // a scene without the second layers holds none
  CubeFirstPass s;
  s.layers = layers;
  s.layer1_size = std::max(16, ctx.options.map_size / 2);
  // Impostor cube maps hold the seen points (each direction's distance) even in a colour-only frame, and with
  // other elements in them (cubeElements) a third cube of their normals and indices.
  with_seen = mode == RenderMode::Impostor;
  follow = maps.cubeElements(mode);
  lens_in_cubes = maps.lensInCubes(mode);
  std::vector<unsigned> formats{GL_RGBA16F};
  if (ctx.options.seen_points || with_seen) formats.push_back(GL_RGBA32F);
  if (follow > 0) formats.push_back(GL_RGBA32F);
  for (size_t e = 0; e < n_el && mode == RenderMode::Impostor; ++e) {
    if (scene.elements[e].type == ElementType::Lens) s.height_maps += maps.updateLensMaps(e);
    else s.surface_maps += maps.updateMirrorMaps(e);
  }
  // Reuse: the cubes drawn last, if nothing they show has changed since (they do not depend on the eye).
  CubeKey key = keyNow(formats.size());
  const std::string stale = staleReason(cache, key);
  cubes_reused = stale.empty() && cubes.size() == n_el;
  if (!cubes_reused) {
    drawn_key = std::move(key);
    layer1_drawn = false;
    reused_frames = 0;
  } else {
    ++reused_frames;
  }
  // The elements other cubes show: each mesh uploaded once (MeshPool slots).
  cube_mesh.assign(n_el, 0);
  const bool cube_draws = !cubes_reused || (layers > 1 && !layer1_drawn);  // what draws into cubes this frame
  std::vector<ElementFrame> in_cubes(n_el);
  for (size_t m = 0; m < n_el && cube_draws; ++m) {
    if (!inCubes(m)) continue;
    in_cubes[m] = prepareElement(scene, int(m), &ctx.grid_cache.get(scene, int(m)));
    cube_mesh[m] = ctx.meshes.next();
    uploadElementGrid(ctx.meshes.slot(), scene, in_cubes[m], Vec3(scene.elements[m].local_to_world[3]));
  }
  // Near planes from what each cube draws: nothing clipped, the depth buffer's precision where it matters.
  if (!cubes_reused || cube_near.size() != n_el) {
    cube_near.assign(n_el, kMinCubeNear_m);
    cube_far.assign(n_el, 1.0);
    for (size_t e = 0; e < n_el; ++e) {
      std::vector<const ElementFrame*> others;
      for (size_t m = 0; m < n_el; ++m)
        if (m != e && inCubes(m) && !in_cubes[m].world_pos.empty()) others.push_back(&in_cubes[m]);
      const Vec3 centre = Vec3(scene.elements[e].local_to_world[3]);
      cube_near[e] = cubeNearPlane(nearestSurface(scene, centre, others));
      cube_far[e] = std::max(cubeFarPlane(scene, centre), 4.0 * cube_near[e]);
    }
  }
  // No cube stays bound to the units the element programs read while cubes are drawn into.
  for (GLenum unit : {GL_TEXTURE0, GL_TEXTURE1}) {
    glActiveTexture(unit);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
  }
  glActiveTexture(GL_TEXTURE0);
  for (size_t e = 0; e < n_el && !cubes_reused; ++e) {
    if (cubes[e]->size != ctx.options.map_size || cubes[e]->colors.size() != formats.size())
      cubes[e]->create(ctx.options.map_size, formats);
    // The second layer's targets exist from here on: the element programs bind them.
    if (layers > 1 && (cubes1[e]->size != s.layer1_size || cubes1[e]->colors.size() != formats.size()))
      cubes1[e]->create(s.layer1_size, formats);
    const auto [c, drawn] = drawCubes(e, 0);
    s.culled.add(c);
    s.drawn_in_cubes += drawn;
  }
  second_layers = layers > 1;
  glFinish();
  s.ms = msSince(t0);
  s.follow = follow;
  s.lens_in_cubes = lens_in_cubes;
  s.lens_count = maps.lensCount();
  noteCubeFirstPass(stages, scene, mode, ctx.options.cull_back_faces, s);
  for (StageTiming& t : stages.stages) {
    if (t.name != stage::kFirstPass) continue;
    if (cubes_reused) {  // the plan's note stays, as what the reused cubes hold
      t.ran = false;
      t.reason = "cube maps reused: drawn " + std::to_string(reused_frames) +
                 " frame(s) ago, and nothing they show has changed since (the environment, every element's pose, "
                 "the mode and map settings; the cubes do not depend on the eye); " +
                 t.note;
      t.note.clear();
      t.ms = 0;
    } else {
      appendNote(t.note, "drawn: " + stale);
    }
  }
}

void CubePass::drawCubeElement(size_t m, const Mat4& view_proj, const Vec3& origin, const MeshBuffers& mesh, bool peel) {
  const Element& el = ctx.scene.elements[m];
  const Vec3 anchor = Vec3(el.local_to_world[3]);
  const bool lens = el.type == ElementType::Lens;
  const Program& p = ctx.programs.cubeGeometry(lens, peel);
  p.use();
  if (peel) p.set("u_peel", kPeelUnit);
  p.set("u_view_proj", toFloat(view_proj));
  p.set("u_offset", glm::vec3(anchor - origin));
  p.set("u_view_origin", glm::vec3(0.0f));
  p.set("u_seen_offset", glm::vec3(anchor - origin));
  setElementMaterial(p, el, int(m));
  if (!lens) maps.setMirrorMaps(p, m);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  draw(mesh);
}

// Layer 0 of element e's cubes: the nearest surfaces. Layer 1 ([Umenhoffer et al.], depth peeling, at half the size):
// the nearest beyond them, what an occluder near the element hides from its origin; where nothing lies
// beyond, the first layer's own texel (shaders/sky.frag, FIRST_LAYER). Layer 1 is drawn in the second pass,
// and only if some pixel's search needs it (drawSecondLayers).
std::pair<CullCount, int> CubePass::drawCubes(size_t e, int layer) {
  const Scene& scene = ctx.scene;
  const size_t n_el = scene.elements.size();
  const Vec3 centre = Vec3(scene.elements[e].local_to_world[3]);
  const Mat4 proj = glm::perspective(kPi / 2, 1.0, cube_near[e], cube_far[e]);
  CubeTarget& c = layer ? *cubes1[e] : *cubes[e];
  if (layer) {  // the first layer's seen points, colour and normals (shaders/sky.frag, FIRST_LAYER)
    const std::vector<unsigned>& first = cubes[e]->colors;
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
        drawCubeElement(m, relativeViewProj(proj, view, centre), centre, ctx.meshes.at(cube_mesh[m]), layer > 0);
        drawn += face == 0;
      }
    culled.add(ctx.environment.draw(view, proj, centre, false, nullptr, false, with_seen, layer > 0));
  }
  if (layer) {
    for (int unit : {kPeelUnit, kFirstCubeUnit, kFirstCubeUnit + 1}) {
      glActiveTexture(GLenum(GL_TEXTURE0 + unit));
      glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    }
    glActiveTexture(GL_TEXTURE0);
  }
  return std::make_pair(culled, drawn);
}

// Impostor with two layers (layer_draw): 0 the first draw, which leaves the pixels whose search ends off a
// surface in the first layer (it discards them, writing no depth); 2 a probe, which counts those pixels (no
// colour, no depth: only what passes the depth test is shaded, and it returns at once); 1 the second draw
// (LAYER_MARCH), which passes the depth test only there: where the first draw kept a fragment, the same
// fragment has the same depth (element.vert's invariant position). A renderer that runs every path of a
// shader with the lanes that do not take it masked off (llvmpipe) pays the second layer's search only there:
// it tests depth before a shader that may discard, and skips blocks of pixels that all fail.
void CubePass::drawElement(size_t e, int layer_draw, const PassCamera& eye) {
  const Element& el = ctx.scene.elements[e];
  const Vec3 anchor = Vec3(el.local_to_world[3]);
  const bool lens = el.type == ElementType::Lens;
  const bool impostor = mode == RenderMode::Impostor;
  const Program& p = impostor ? ctx.programs.impostor(lens, maps.impostorChannels(e), follow, lens_in_cubes, layers,
                                                      layer_draw)
                              : ctx.programs.envmap(lens);
  p.use();
  p.set("u_view_proj", toFloat(eye.view_proj));
  p.set("u_offset", glm::vec3(anchor - eye.origin));
  p.set("u_view_origin", glm::vec3(0.0f));
  setLights(p, ctx.scene, eye.origin);
  setElementMaterial(p, el, int(e));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[0]);
  glActiveTexture(GL_TEXTURE1);
  if (cubes[e]->colors.size() > 1) glBindTexture(GL_TEXTURE_CUBE_MAP, cubes[e]->colors[1]);
  glActiveTexture(GL_TEXTURE0);
  p.set("u_cube", 0);
  p.set("u_seen_cube", 1);
  p.set("u_seen_offset", glm::vec3(anchor - eye.origin));
  if (layers > 1 && follow == 0) {  // one element: its second layer after its own maps
    for (int a = 0; a < 2; ++a) {
      glActiveTexture(GLenum(GL_TEXTURE0 + kFirstCubeUnit + a));
      glBindTexture(GL_TEXTURE_CUBE_MAP, cubes1[e]->colors[size_t(a)]);
    }
    glActiveTexture(GL_TEXTURE0);
    p.set("u_cube1", kFirstCubeUnit);
    p.set("u_seen_cube1", kFirstCubeUnit + 1);
  }
  if (impostor && !lens) maps.setMirrorMaps(p, e);
  if (follow > 0) maps.setCubeElements(p, e, eye.origin, layers, cubes, cubes1);
  if (impostor && lens) maps.setLensMaps(p, e);
  if (impostor) p.set("u_seen_channel", ctx.options.seen_channel < 0 ? 1 : std::min(ctx.options.seen_channel, 2));
  draw(ctx.meshes.at(element_slot[e]));
}

std::string CubePass::drawElements(RenderMode, const PassCamera& eye, const Framebuffer& target) {
  const Scene& scene = ctx.scene;
  const size_t n_el = scene.elements.size();
  element_slot.assign(n_el, 0);
  frames.clear();
  for (size_t e = 0; e < n_el; ++e) {
    target.bind();
    ElementFrame f = prepareElement(scene, int(e), &ctx.grid_cache.get(scene, int(e)));
    if (scene.elements[e].type == ElementType::Lens && mode == RenderMode::Envmap)
      traceVertexRays(ctx.rays, f, eye.origin, VertexStageOptions{});
    element_slot[e] = ctx.meshes.next();
    uploadElementGrid(ctx.meshes.slot(), scene, f, Vec3(scene.elements[e].local_to_world[3]));
    drawElement(e, 0, eye);
    std::vector<char> in_cube(n_el, 0);
    for (size_t m = 0; m < n_el; ++m) in_cube[m] = inCubes(m);
    assessCubeQuality(ctx.rays, f, mode, eye.origin, cube_near[e], cube_far[e], in_cube);
    frames.push_back(std::move(f));
  }
  return second_layers ? drawSecondLayers(eye, target) : std::string();
}

// The second layers, where some pixel needs them: the probe counts each element's pixels left by its first
// draw; the second layers' cubes are drawn if there are any, and the second draw of each such element.
std::string CubePass::drawSecondLayers(const PassCamera& eye, const Framebuffer& target) {
  const size_t n_el = ctx.scene.elements.size();
  const auto t_layers = Clock::now();
  std::vector<GLuint> queries(n_el);
  glGenQueries(GLsizei(n_el), queries.data());
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  for (size_t e = 0; e < n_el; ++e) {
    glBeginQuery(GL_SAMPLES_PASSED, queries[e]);
    drawElement(e, 2, eye);
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
  if (total == 0) return secondLayersSkippedNote();
  // No cube stays bound to a unit while cubes are drawn into (the element programs bound the second
  // layers from kFirstCubeUnit on).
  for (int unit = kFirstCubeUnit; unit < std::min(ctx.max_texture_units, kFirstCubeUnit + 6 * int(n_el)); ++unit) {
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
  }
  glActiveTexture(GL_TEXTURE0);
  CullCount layer_culled;
  const bool layer1_reused = layer1_drawn;  // drawn with the first layers' key (prepare voids it with them)
  for (size_t e = 0; e < n_el && !layer1_reused; ++e) layer_culled.add(drawCubes(e, 1).first);
  layer1_drawn = true;
  target.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  for (size_t e = 0; e < n_el; ++e)
    if (left[e] > 0) drawElement(e, 1, eye);
  glFinish();
  return secondLayersNote(msSince(t_layers),
                          layer1_reused ? std::string("reused, drawn in an earlier frame")
                                        : cullNote(layer_culled, ctx.options.cull_back_faces),
                          total);
}

}  // namespace pvrr::gl

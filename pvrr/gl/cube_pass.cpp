#include "pvrr/gl/cube_pass.h"

#include <algorithm>
#include <cmath>
#include <optional>

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
  k.poses = posesOf(ctx.scene);
  for (size_t m = 0; m < ctx.scene.meshes.size(); ++m) k.mesh_boxes.push_back(ctx.environment.worldBox(m));
  return k;
}

CubePass::Staleness CubePass::staleness(const FrameCache* cache, const CubeKey& k) const {
  if (!cache) return {"no frame cache (a single frame)", {}};
  if (cache->environment_changed && !cache->only_meshes_moved)
    return {"the environment changed (or a new frame cache)", {}};
  if (!drawn_key) return {"first frame", {}};
  const CubeKey& d = *drawn_key;
  if (d.mode != k.mode || d.map_size != k.map_size || d.layers != k.layers || d.follow != k.follow ||
      d.formats != k.formats || d.lens_in_cubes != k.lens_in_cubes)
    return {"the mode or the map settings changed", {}};
  const std::string element = elementMoved(ctx.scene, d.poses);
  if (!element.empty()) return {element, {}};
  std::vector<size_t> moved = meshesMoved(ctx.scene, d.poses);
  if (moved.empty()) return {};
  const std::string why = meshesMovedReason(ctx.scene, moved);
  const bool all_animated =
      d.mesh_boxes.size() == ctx.scene.meshes.size() &&
      std::all_of(moved.begin(), moved.end(), [&](size_t m) { return ctx.scene.meshAnimated(m); });
  if (!all_animated) return {why + " (not only animated meshes)", {}};
  if (ctx.environment.shadowed())
    return {why + ", and a light casts shadows: their shadows on the static surfaces moved too", {}};
  if (movedNearCube(moved))
    return {why + ", nearer to a cube than twice its near plane (the cubes' depth range is drawn again)", {}};
  if (ctx.environment.occludes(moved))
    return {why + ", and an ambient occluder moved: its occlusion of the static surfaces moved too", {}};
  return {"", std::move(moved)};
}

namespace {

// A cube face's camera at `centre`: view (world) and projection.
Mat4 faceView(const Vec3& centre, int face) { return glm::lookAt(centre, centre + kCubeDir[face], kCubeUp[face]); }

// The window rectangle {x, y, width, height} of a face of side `size` that holds every texel the boxes (world)
// can cover through view_proj, or nothing when no box reaches into the face's frustum. The part of a box
// in front of the camera projects into the hull of its projected corners (perspective maps segments in
// front of the camera to segments); a box reaching behind the camera's plane takes the whole face. Widened by
// a texel against rounding, and by `margin` texels more.
std::optional<std::array<int, 4>> faceRect(const Mat4& view_proj, const std::vector<std::array<Vec3, 2>>& boxes,
                                           int size, int margin) {
  // The frustum's sides widened by `margin` texels: a box just beside the face still takes its edge texels.
  const double widen = 1.0 + 2.0 * margin / size;
  double x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
  bool any = false, whole = false;
  for (const auto& box : boxes) {
    Vec4 clip[8];
    for (int c = 0; c < 8; ++c)
      clip[c] = view_proj *
                Vec4((c & 1) ? box[1].x : box[0].x, (c & 2) ? box[1].y : box[0].y, (c & 4) ? box[1].z : box[0].z, 1.0);
    bool outside = false;  // every corner beyond one plane of the frustum
    for (int axis = 0; axis < 3 && !outside; ++axis)
      for (double sign : {-1.0, 1.0}) {
        bool all = true;
        for (int c = 0; c < 8 && all; ++c) all = sign * clip[c][axis] > clip[c].w * (axis < 2 ? widen : 1.0);
        outside = outside || all;
      }
    if (outside) continue;
    any = true;
    for (int c = 0; c < 8; ++c) {
      if (!(clip[c].w > 1e-12)) {
        whole = true;
        break;
      }
      x0 = std::min(x0, clip[c].x / clip[c].w), x1 = std::max(x1, clip[c].x / clip[c].w);
      y0 = std::min(y0, clip[c].y / clip[c].w), y1 = std::max(y1, clip[c].y / clip[c].w);
    }
  }
  if (!any) return std::nullopt;
  if (whole) return std::array<int, 4>{0, 0, size, size};
  auto window = [size, margin](double ndc, bool up) {
    const double p = (ndc + 1.0) * 0.5 * size;
    return std::clamp(up ? int(std::ceil(p)) + 1 + margin : int(std::floor(p)) - 1 - margin, 0, size);
  };
  const int wx0 = window(x0, false), wx1 = window(x1, true), wy0 = window(y0, false), wy1 = window(y1, true);
  if (wx1 <= wx0 || wy1 <= wy0) return std::nullopt;
  return std::array<int, 4>{wx0, wy0, wx1 - wx0, wy1 - wy0};
}

}  // namespace

Mat4 CubePass::cubeProjection(size_t e) const {
  return glm::perspective(kPi / 2, 1.0, cube_near[e], cube_far[e]);
}

// The near planes (cubeNearPlane) are half the distance to the nearest surface a cube drew: a moving mesh whose
// box comes within twice that is as near as the nearest surface (or nearer), so a cube's depth range as a full
// redraw would choose it may differ, or the mesh be clipped: the cubes are drawn again whole.
bool CubePass::movedNearCube(const std::vector<size_t>& moved) const {
  for (size_t e = 0; e < cube_near.size() && e < ctx.scene.elements.size(); ++e) {
    const Vec3 centre = Vec3(ctx.scene.elements[e].local_to_world[3]);
    for (const size_t m : moved) {
      const std::array<Vec3, 2> box = ctx.environment.worldBox(m);
      const Vec3 nearest = glm::clamp(centre, box[0], box[1]);
      if (glm::length(nearest - centre) < 2.0 * cube_near[e]) return true;
    }
  }
  return false;
}

int CubePass::redrawWhereMoved(size_t e, int layer, const std::vector<size_t>& moved,
                               const std::vector<std::array<Vec3, 2>>& before, CullCount& culled, size_t& texels) {
  const Vec3 centre = Vec3(ctx.scene.elements[e].local_to_world[3]);
  const Mat4 proj = cubeProjection(e);
  std::vector<std::array<Vec3, 2>> boxes;
  for (const size_t m : moved) {
    boxes.push_back(before[m]);
    boxes.push_back(ctx.environment.worldBox(m));
  }
  int faces = 0, drawn = 0;
  for (int face = 0; face < 6; ++face) {
    // Layer 1 peels against layer 0 read with bilinear (and seamless) filtering: half a layer-1 texel of
    // layer 0's change around, on this face or across an edge; two texels more cover it.
    const int side = (layer ? cubes1 : cubes)[e]->size;
    const auto rect = faceRect(proj * faceView(centre, face), boxes, side, layer ? 2 : 0);
    if (!rect) continue;
    glEnable(GL_SCISSOR_TEST);
    glScissor((*rect)[0], (*rect)[1], (*rect)[2], (*rect)[3]);
    drawFace(e, layer, face, culled, drawn);  // selectFace's clear keeps to the scissor rectangle too
    glDisable(GL_SCISSOR_TEST);
    ++faces;
    texels += size_t((*rect)[2]) * size_t((*rect)[3]);
  }
  return faces;
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
  // Reuse: the cubes drawn last, if nothing they show has changed since (they do not depend on the eye), or
  // with only animated meshes moved, drawn again only where those are and were (the static/dynamic split).
  CubeKey key = keyNow(formats.size());
  const Staleness stale = staleness(cache, key);
  cubes_reused = stale.full.empty() && cubes.size() == n_el;
  const bool partial = cubes_reused && !stale.moved.empty();
  std::vector<std::array<Vec3, 2>> boxes_before;
  if (!cubes_reused) {
    drawn_key = std::move(key);
    layer1_drawn = false;
    reused_frames = 0;
  } else {
    ++reused_frames;
    if (partial) {
      boxes_before = drawn_key->mesh_boxes;
      drawn_key = std::move(key);  // the second layers keep layer1_key: updated in place where needed too
    }
  }
  const bool layer1_stale = layers > 1 && layer1_drawn && !meshesMoved(scene, layer1_key.poses).empty();
  // The elements other cubes show: each mesh uploaded once (MeshPool slots).
  cube_mesh.assign(n_el, 0);
  // What draws into cubes this frame.
  const bool cube_draws = !cubes_reused || partial || (layers > 1 && !layer1_drawn) || layer1_stale;
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
  int faces_redrawn = 0;
  size_t texels_redrawn = 0;
  for (size_t e = 0; e < n_el && partial; ++e)
    faces_redrawn += redrawWhereMoved(e, 0, stale.moved, boxes_before, s.culled, texels_redrawn);
  second_layers = layers > 1;
  glFinish();
  s.ms = msSince(t0);
  s.follow = follow;
  s.lens_in_cubes = lens_in_cubes;
  s.lens_count = maps.lensCount();
  noteCubeFirstPass(stages, scene, mode, ctx.options.cull_back_faces, s);
  for (StageTiming& t : stages.stages) {
    if (t.name != stage::kFirstPass) continue;
    if (partial) {
      const double share =
          100.0 * double(texels_redrawn) / (6.0 * double(n_el) * ctx.options.map_size * ctx.options.map_size);
      appendNote(t.note, "updated in place: " + meshesMovedReason(scene, stale.moved) +
                             "; drawn again only where the moving meshes are or were (" +
                             std::to_string(faces_redrawn) + " of " + std::to_string(6 * n_el) + " faces, " +
                             fmt("%.1f", share) + " % of the texels), the rest kept from the cubes drawn " +
                             std::to_string(reused_frames) + " frame(s) ago");
    } else if (cubes_reused) {  // the plan's note stays, as what the reused cubes hold
      t.ran = false;
      t.reason = "cube maps reused: drawn " + std::to_string(reused_frames) +
                 " frame(s) ago, and nothing they show has changed since (the environment, every element's pose, "
                 "the mode and map settings; the cubes do not depend on the eye); " +
                 t.note;
      t.note.clear();
      t.ms = 0;
    } else {
      appendNote(t.note, "drawn: " + stale.full);
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
  CullCount culled;
  int drawn = 0;
  for (int face = 0; face < 6; ++face) drawFace(e, layer, face, culled, drawn);
  return std::make_pair(culled, drawn);
}

void CubePass::drawFace(size_t e, int layer, int face, CullCount& culled, int& drawn) {
  const Scene& scene = ctx.scene;
  const size_t n_el = scene.elements.size();
  const Vec3 centre = Vec3(scene.elements[e].local_to_world[3]);
  const Mat4 proj = cubeProjection(e);
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
  c.selectFace(face);
  const Mat4 view = faceView(centre, face);
  for (size_t m = 0; m < n_el; ++m)
    if (m != e && inCubes(m)) {
      drawCubeElement(m, relativeViewProj(proj, view, centre), centre, ctx.meshes.at(cube_mesh[m]), layer > 0);
      drawn += face == 0;
    }
  culled.add(ctx.environment.draw(view, proj, centre, false, nullptr, false, with_seen, layer > 0));
  if (layer) {
    for (int unit : {kPeelUnit, kFirstCubeUnit, kFirstCubeUnit + 1}) {
      glActiveTexture(GLenum(GL_TEXTURE0 + unit));
      glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    }
    glActiveTexture(GL_TEXTURE0);
  }
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
  if (impostor) {  // what a search that escapes past an occluder sees (shaders/impostor_search.glsl, g_escaped)
    p.set("u_background", glm::vec3(ctx.scene.render.background));
    p.set("u_far", float(ctx.scene.render.far_distance_m));
  }
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
  // Drawn with the first layers' key (a full redraw of the first layers voids them), or with an earlier
  // pose of the animated meshes: then updated where those are and were.
  const bool layer1_reused = layer1_drawn;
  const std::vector<size_t> moved = layer1_reused ? meshesMoved(ctx.scene, layer1_key.poses) : std::vector<size_t>{};
  size_t texels = 0;
  int faces = 0;
  for (size_t e = 0; e < n_el && !layer1_reused; ++e) layer_culled.add(drawCubes(e, 1).first);
  for (size_t e = 0; e < n_el && !moved.empty(); ++e)
    faces += redrawWhereMoved(e, 1, moved, layer1_key.mesh_boxes, layer_culled, texels);
  layer1_drawn = true;
  layer1_key = *drawn_key;
  target.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  for (size_t e = 0; e < n_el; ++e)
    if (left[e] > 0) drawElement(e, 1, eye);
  glFinish();
  return secondLayersNote(msSince(t_layers),
                          layer1_reused && !moved.empty()
                              ? "updated in place where the moving meshes are or were (" + std::to_string(faces) +
                                    " faces, " + std::to_string(texels) + " texels), drawn in an earlier frame"
                          : layer1_reused ? std::string("reused, drawn in an earlier frame")
                                        : cullNote(layer_culled, ctx.options.cull_back_faces),
                          total);
}

}  // namespace pvrr::gl

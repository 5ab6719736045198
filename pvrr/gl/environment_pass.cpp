#include "pvrr/gl/environment_pass.h"

#include <algorithm>

#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/ao_vertex_receivers.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/impostor_maps.h"
#include "pvrr/gl/caustic_pass.h"
#include "pvrr/gl/shadow_pass.h"
#include "pvrr/method/view_volume.h"

namespace pvrr::gl {

namespace {
// The centre of projection this far (m) behind a face's plane: the face is back-facing for the rasterizer too.
constexpr double kHiddenFaceMargin = 1e-3;
}  // namespace

void setLights(const Program& p, const Scene& scene, const Vec3& origin) {
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

EnvironmentPass::EnvironmentPass(const Scene& s, const RendererOptions& o, const Programs& p)
    : scene(s), options(o), programs(p) {
  programs.sky(false);  // built now, as the meshes' programs below
  glGenVertexArrays(1, &empty_vao);
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
  env_bounds.resize(scene.meshes.size());
  env_motion.resize(scene.meshes.size());
  env_groups.resize(scene.meshes.size());
  group_faces = ambientOcclusionSkipReason(scene).empty();
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvMesh& mesh = scene.meshes[m];
    // Faceted: each triangle's three normals equal and perpendicular to it (a supplied normal tilted from
    // its face would make the per-vertex two-sided flip differ from the per-fragment one). Decided once: an
    // animated mesh moves rigidly, which keeps a faceted mesh's normals equal (each is rotated alike).
    env_faceted.push_back(std::all_of(mesh.triangles.begin(), mesh.triangles.end(), [&](const auto& t) {
      const glm::vec3 n = mesh.normals[t.x];
      const Vec3 face = glm::cross(Vec3(mesh.positions[t.y] - mesh.positions[t.x]), Vec3(mesh.positions[t.z] - mesh.positions[t.x]));
      const double len = glm::length(face);
      const bool perpendicular = len == 0 || std::abs(glm::dot(face / len, Vec3(n))) >= 1 - 1e-6;
      return perpendicular && glm::length(mesh.normals[t.y] - n) <= 1e-6f && glm::length(mesh.normals[t.z] - n) <= 1e-6f;
    }));
    env_textured.push_back(scene.materials[size_t(mesh.material)].texture >= 0);
    upload(m);
    // Its program, built now (not in the first frame's first pass) so that its compile time and any
    // compile error come with the renderer.
    programs.env(env_faceted.back(), env_textured.back(), false);
  }
  checkGlError("uploading the environment");
}

void EnvironmentPass::upload(size_t m) {
  const EnvMesh& mesh = scene.meshes[m];
  std::vector<float> data;
  data.reserve(mesh.positions.size() * 8);
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3 pos = mesh.positions[i], n = mesh.normals[i];
    const glm::vec2 uv = mesh.uvs[i];
    data.insert(data.end(), {pos.x, pos.y, pos.z, n.x, n.y, n.z, uv.x, uv.y});
  }
  std::vector<uint32_t> idx;
  idx.reserve(mesh.triangles.size() * 3);
  std::vector<FaceGroup>& groups = env_groups[m];
  groups.clear();
  if (group_faces && env_faceted[m]) {
    // Each triangle's plane: its normal (exactly) and offset along it (within float rounding).
    constexpr size_t kMaxFaceGroups = 12;
    std::vector<double> offsets;
    std::vector<size_t> of(mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::vec3 n = mesh.normals[mesh.triangles[t].x], p = mesh.positions[mesh.triangles[t].x];
      const double d = glm::dot(Vec3(n), Vec3(p));
      size_t g = 0;
      while (g < groups.size() && !(glm::vec3(groups[g].normal) == n && std::abs(offsets[g] - d) <= 1e-5 * (1 + std::abs(d)))) ++g;
      if (g == groups.size()) {
        if (g == kMaxFaceGroups) {
          groups.clear();
          break;
        }
        FaceGroup f;
        f.normal = Vec3(n);
        f.point = Vec3(p);
        f.box = {Vec3(kInf), Vec3(-kInf)};
        groups.push_back(f);
        offsets.push_back(d);
      }
      of[t] = g;
    }
    for (size_t g = 0; g < groups.size(); ++g) {
      groups[g].first = int(idx.size());
      for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (of[t] != g) continue;
        groups[g].triangles.push_back(uint32_t(t));
        const auto& tri = mesh.triangles[t];
        idx.insert(idx.end(), {tri.x, tri.y, tri.z});
        for (const uint32_t v : {tri.x, tri.y, tri.z}) {
          groups[g].box[0] = glm::min(groups[g].box[0], Vec3(mesh.positions[v]));
          groups[g].box[1] = glm::max(groups[g].box[1], Vec3(mesh.positions[v]));
        }
      }
      groups[g].count = int(idx.size()) - groups[g].first;
    }
  }
  if (groups.empty())
    for (const auto& t : mesh.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
  uploadMesh(env_meshes[m], data, {3, 3, 2}, idx);
  Vec3 lo(mesh.positions.empty() ? glm::vec3(0) : mesh.positions[0]), hi(lo);
  for (const glm::vec3& pos : mesh.positions) {
    lo = glm::min(lo, Vec3(pos));
    hi = glm::max(hi, Vec3(pos));
  }
  env_bounds[m] = {lo, hi};
  env_motion[m] = scene.meshMotion(m);
}

std::vector<size_t> EnvironmentPass::update() {
  std::vector<size_t> moved;
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.meshAnimated(m) && scene.meshMotion(m) != env_motion[m]) moved.push_back(m);
  for (const size_t m : moved) upload(m);
  if (!moved.empty()) checkGlError("updating the animated environment meshes");
  return moved;
}

std::array<Vec3, 2> EnvironmentPass::worldBox(size_t m) const {
  return {env_bounds[m][0] + scene.meshes[m].anchor, env_bounds[m][1] + scene.meshes[m].anchor};
}

bool EnvironmentPass::shadowed() const { return shadows_ && shadows_->active(); }

bool EnvironmentPass::occludes(const std::vector<size_t>& moved) const {
  if (!ao_ || !ao_->active()) return false;
  return std::any_of(moved.begin(), moved.end(), [&](size_t m) { return scene.meshes[m].occluder >= 0; });
}

EnvironmentPass::~EnvironmentPass() {
  for (auto& m : env_meshes) m.release();
  if (empty_vao) glDeleteVertexArrays(1, &empty_vao);
}

std::vector<std::array<Vec3, 2>> EnvironmentPass::boxes(const Vec3& origin) const {
  std::vector<std::array<Vec3, 2>> out(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Vec3 to_anchor = scene.meshes[m].anchor - origin;
    out[m] = {env_bounds[m][0] + to_anchor, env_bounds[m][1] + to_anchor};
  }
  return out;
}

std::vector<size_t> EnvironmentPass::drawOrder(const std::vector<std::array<Vec3, 2>>& b, bool reversed_depth) const {
  if (options.sort_environment) return depthSortedDrawOrder(b, reversed_depth);
  std::vector<size_t> order(b.size());
  for (size_t m = 0; m < order.size(); ++m) order[m] = m;
  return order;
}

void EnvironmentPass::drawCasters(const Program& p, const Mat4& view_proj, const Vec3& origin) const {
  p.use();
  p.set("u_view_proj", toFloat(view_proj));
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    p.set("u_offset", glm::vec3(scene.meshes[m].anchor - origin));
    gl::draw(env_meshes[m]);
  }
}

CullCount EnvironmentPass::draw(const Mat4& view, const Mat4& proj, const Vec3& origin, bool reversed_depth,
                                const Vec3* rays_from, bool planes, bool with_seen, bool peel,
                                const Vec4* clip_plane) const {
  const Mat4 vp = relativeViewProj(proj, view, origin);
  // The clip plane on camera-relative points q = p - origin: dot(n, q) + (d + dot(n, origin)).
  const glm::vec4 clip_relative =
      clip_plane ? glm::vec4(Vec4(Vec3(*clip_plane), clip_plane->w + glm::dot(Vec3(*clip_plane), origin)))
                 : glm::vec4(0.0f);
  const Program& sky = programs.sky(planes, with_seen, peel);
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
  // The programs of the kinds of mesh the scene has, [ambient occlusion][faceted][textured], set up for this
  // pass when first drawn; a draw's ambient occlusion variant is chosen per mesh or face (AoFields::receiver).
  const Program* kinds[5][2][2] = {};
  glm::vec4 ao_image_map(0.0f);  // the occlusion image's coordinates (shaders/ambient_occlusion.glsl)
  auto program = [&](AoReceiver ao, bool faceted, bool textured) -> const Program& {
    const Program*& p = kinds[int(ao)][faceted][textured];
    if (p) return *p;
    p = &programs.env(faceted, textured, planes, with_seen, peel, ao);
    p->use();
    if (peel) p->set("u_peel", kPeelUnit);
    p->set("u_view_proj", toFloat(vp));
    if (clip_plane) p->set("u_clip_plane", clip_relative);
    p->set("u_view_origin", rays_from ? glm::vec3(*rays_from - origin) : glm::vec3(0.0f));
    if (textured) p->set("u_texture", 0);
    setLights(*p, scene, origin);
    if (shadows_) shadows_->bind(*p, origin);
    if (caustics_) caustics_->bind(*p, origin);
    if (ao_ && ao != AoReceiver::Vertex) ao_->bind(*p, origin);
    if (ao == AoReceiver::Screen) {
      p->set("u_ao_image", ao_->unit());
      p->set("u_ao_image_map", ao_image_map);
    }
    glActiveTexture(GL_TEXTURE0);
    return *p;
  };
  // Indices [first, first + count) of mesh m (or of the vertex-value grid `grid` of one of its faces), drawn with
  // ambient occlusion d.
  auto drawPart = [&](size_t m, const AoFields::Draw& d, int first, int count, const MeshBuffers* grid) {
    const EnvMesh& mesh = scene.meshes[m];
    const Program& p = program(d.kind, env_faceted[m], env_textured[m]);
    p.use();
    p.set("u_offset", glm::vec3(mesh.anchor - origin));
    p.set("u_albedo", glm::vec3(scene.materials[size_t(mesh.material)].color));
    if (ao_) ao_->setReceiver(p, m, d);
    if (env_textured[m]) glBindTexture(GL_TEXTURE_2D, textures[size_t(scene.materials[size_t(mesh.material)].texture)].name());
    glBindVertexArray(grid ? grid->vao : env_meshes[m].vao);
    glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(size_t(first) * sizeof(uint32_t)));
  };
  const Vec3 viewer = rays_from ? *rays_from : origin;  // where the two-sided normals face
  // Back faces of closed convex meshes that near clipping cannot cut open (RendererOptions::cull_back_faces,
  // NearClip): a ray from the centre of projection to a back-face point first crosses a front face
  // of the same solid, itself beyond the near plane, which the depth test keeps instead. Not with reversed
  // depth, where the farther face wins.
  const bool may_cull = options.cull_back_faces && !reversed_depth && !clip_plane;
  if (clip_plane) glEnable(GL_CLIP_DISTANCE0);
  const NearClip near_clip(vp);
  glDisable(GL_CULL_FACE);  // whatever an interrupted pass left
  if (may_cull) {
    glCullFace(GL_BACK);
    glFrontFace(facingTrianglesWindCounterClockwise(vp) ? GL_CCW : GL_CW);
  }
  // What to draw, in order: the meshes, or their faces (a plane's normal, turned to the viewer as the shader turns
  // it), consecutive faces with the same ambient occlusion in one draw.
  struct Part {
    size_t m;
    bool cull;
    AoFields::Draw ao;
    int first, count;
    const MeshBuffers* grid = nullptr;  // a face drawn with vertex values (AoReceiver::Vertex): its grid
  };
  std::vector<Part> parts;
  // How each mesh or face is ambient-occluded (AoFields::receiver; its vertex-value grid where it has one), kept
  // while nothing moves: per mesh, face (-1: the whole mesh) and side the viewer is on (-1, 0, 1).
  if (ao_ && scene.mesh_motion != ao_choices_motion) {
    ao_choices.clear();
    ao_choices_motion = scene.mesh_motion;
  }
  auto choice = [&](size_t m, int g, int side) -> const AoChoice& {
    const auto [it, added] = ao_choices.try_emplace({m, g, side});
    if (!added) return it->second;
    AoChoice& c = it->second;
    const EnvMesh& mesh = scene.meshes[m];
    AoVertexReceivers* receivers = ao_->vertexReceivers();
    if (g < 0) {
      c.draw = ao_->receiver(m, worldBox(m));
      if (receivers && c.draw.kind != AoReceiver::None) receivers->fallback(m, env_faceted[m] ? "more than 12 planes" : "not faceted");
      return c;
    }
    const FaceGroup& f = env_groups[m][size_t(g)];
    const Vec3 facing = side > 0 ? -f.normal : f.normal;
    c.draw = ao_->receiver(m, {f.box[0] + mesh.anchor, f.box[1] + mesh.anchor}, side != 0 ? &facing : nullptr);
    // A face some field counts for: its vertex-value grid where it has one (made or remade now if needed).
    if (c.draw.kind != AoReceiver::None && receivers) c.grid = receivers->grid(m, size_t(g), f.triangles, f.normal);
    if (c.grid) c.draw = AoFields::Draw{AoReceiver::Vertex, {}};
    return c;
  };
  CullCount count;
  const std::vector<std::array<Vec3, 2>> relative = boxes(origin);  // camera-relative
  for (const size_t m : drawOrder(relative, reversed_depth)) {
    const EnvMesh& mesh = scene.meshes[m];
    const bool cull = may_cull && mesh.closed_convex && near_clip.cannotOpen(relative[m][0], relative[m][1]);
    count.drawn += mesh.closed_convex;
    count.culled += cull;
    if (!ao_ || env_groups[m].empty()) {
      parts.push_back({m, cull, ao_ ? choice(m, -1, 0).draw : AoFields::Draw{}, 0, env_meshes[m].count});
      continue;
    }
    const std::vector<FaceGroup>& groups = env_groups[m];
    std::vector<const AoChoice*> chosen(groups.size());
    bool any_grid = false, all_grids = true;  // some face has a grid; every face a field counts for has one
    uint32_t mask = 0;
    static const AoChoice kHidden{};  // no occlusion, no grid
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      const FaceGroup& g = groups[gi];
      // A face of a culled mesh with the centre of projection behind its plane (by more than a millimetre, so
      // that the sign agrees with the rasterizer's) is culled whole: its grid would buy nothing, so it keeps its
      // own triangles (issue 24's cost: the kerbs' and buildings' hidden faces, about a fifth of the triangles).
      if (cull && glm::dot(g.normal, g.point + mesh.anchor - origin) > kHiddenFaceMargin) {
        chosen[gi] = &kHidden;
        continue;
      }
      const double side = glm::dot(g.normal, g.point + mesh.anchor - viewer);
      chosen[gi] = &choice(m, int(gi), side > 0 ? 1 : side < 0 ? -1 : 0);
      any_grid |= chosen[gi]->grid != nullptr;
      all_grids &= chosen[gi]->grid != nullptr || chosen[gi]->draw.kind == AoReceiver::None;
      mask |= chosen[gi]->grid ? 1u << gi : 0u;
    }
    // Every face with occlusion has a grid: the mesh in one draw, its faces' grids and the other faces (holding
    // zeros) in one buffer (AoVertexReceivers::merged), kept per set of faces drawn as grids.
    if (any_grid && all_grids) {
      const auto [it, added] = ao_choices.try_emplace({m, -2, int(mask)});
      if (added) {
        std::vector<AoVertexReceivers::Face> faces(groups.size());
        for (size_t gi = 0; gi < groups.size(); ++gi)
          faces[gi] = {&groups[gi].triangles, groups[gi].normal, chosen[gi]->grid != nullptr};
        const AoVertexReceivers::Merged* merged = ao_->vertexReceivers()->merged(m, faces);
        it->second.draw = AoFields::Draw{AoReceiver::Vertex, {}};
        it->second.grid = merged ? &merged->buffers : nullptr;
        it->second.plain = merged ? merged->plain : 0;
      }
      if (const AoChoice& c = it->second; c.grid) {
        // Its triangles without occlusion (below kAoValueNegligible) first, drawn without the values.
        if (c.plain > 0) parts.push_back({m, cull, AoFields::Draw{}, 0, c.plain, c.grid});
        if (c.plain < c.grid->count) parts.push_back({m, cull, c.draw, c.plain, c.grid->count - c.plain, c.grid});
        continue;
      }
    }
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      const FaceGroup& g = groups[gi];
      const AoChoice& c = *chosen[gi];
      if (c.grid) {
        parts.push_back({m, cull, c.draw, 0, c.grid->count, c.grid});
        continue;
      }
      if (parts.empty() || parts.back().m != m || !(parts.back().ao == c.draw) || parts.back().grid)
        parts.push_back({m, cull, c.draw, g.first, 0});
      parts.back().count += g.count;
    }
  }
  // The static receivers' occlusion, evaluated into the pass's low-resolution occlusion image (OcclusionImage::kFactor
  // times fewer pixels per axis) and read from it bilinearly: fewer evaluations of the fields, one texture lookup
  // per fragment whatever the number of occluders. Not in the zooming-region and peeling passes.
  const bool image = ao_ && ao_->active() && !reversed_depth && !peel;
  auto screen = [&](const Part& part) {
    return image && (part.ao.kind == AoReceiver::Ground || part.ao.kind == AoReceiver::Volume) && !scene.meshAnimated(part.m);
  };
  if (std::any_of(parts.begin(), parts.end(), screen)) {
    ao_image.begin();
    // The static receivers alone, nearest first: a moving one, and what is drawn without occlusion, hide nothing
    // here, so that the image about a car's outline holds the ground behind it, not the car.
    const Program* occlusion[3][2] = {};
    bool culling = false;
    for (const Part& part : parts) {
      if (!screen(part)) continue;
      const Program*& p = occlusion[int(part.ao.kind)][env_faceted[part.m]];
      if (!p) {
        p = &programs.envOcclusion(env_faceted[part.m], part.ao.kind);
        p->use();
        p->set("u_view_proj", toFloat(vp));
        if (clip_plane) p->set("u_clip_plane", clip_relative);
        p->set("u_view_origin", rays_from ? glm::vec3(*rays_from - origin) : glm::vec3(0.0f));
        ao_->bind(*p, origin);
        glActiveTexture(GL_TEXTURE0);
      }
      if (part.cull != culling) {
        part.cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
        culling = part.cull;
      }
      p->use();
      p->set("u_offset", glm::vec3(scene.meshes[part.m].anchor - origin));
      ao_->setReceiver(*p, part.m, part.ao);
      glBindVertexArray(env_meshes[part.m].vao);
      glDrawElements(GL_TRIANGLES, part.count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(size_t(part.first) * sizeof(uint32_t)));
    }
    glDisable(GL_CULL_FACE);
    ao_image.end(ao_->unit());
    ao_image_map = ao_image.coordinates();
  }
  bool culling = false;
  for (const Part& part : parts) {
    if (part.cull != culling) {
      part.cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
      culling = part.cull;
    }
    drawPart(part.m, screen(part) ? AoFields::Draw{AoReceiver::Screen, {}} : part.ao, part.first, part.count, part.grid);
  }
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  if (clip_plane) glDisable(GL_CLIP_DISTANCE0);
  if (!reversed_depth) {  // the sky triangle lies at depth 1: it passes only where nothing was drawn
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    drawSky();
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
  }
  return count;
}

}  // namespace pvrr::gl

#include "pvrr/gl/caustic_pass.h"

#include <algorithm>

#include "pvrr/base/error.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/texture_units.h"
#include "pvrr/gl/stage_notes.h"

namespace pvrr::gl {

namespace {

// RGBA32F colour textures of w x h, nearest (the photon maps: read with texelFetch) or linear (light maps).
void makeTexture2D(unsigned& tex, int w, int h) {
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

std::string planNote(const CausticPlan& plan, int map_size) {
  std::string note = std::to_string(plan.meshes.size()) + " photon mesh" + (plan.meshes.size() == 1 ? "" : "es") +
                     " (" + std::to_string(plan.traced) + " exact photons traced in " +
                     std::to_string(int(plan.elapsed_ms)) + " ms), " + std::to_string(map_size) + "^2 " +
                     "photons each, " + std::to_string(plan.receivers.size()) + " receiver" +
                     (plan.receivers.size() == 1 ? "" : "s");
  for (const std::string& n : plan.notes) note += "; " + n;
  return note;
}

}  // namespace

std::vector<std::string> causticDefines(const Scene& scene) {
  if (causticLights(scene).empty()) return {};
  return {"#define CAUSTICS"};
}

CausticPass::CausticPass(const Scene& scene, const RayScene& rays, const Programs& programs, int max_texture_units,
                         int map_size)
    : scene_(scene), rays_(rays), programs_(programs), unit_(units::causticMaps(max_texture_units)), map_size_(map_size) {
  if (map_size_ < 1) throw Error("caustics: the caustic map needs a positive size");
  if (!active()) return;
  programs_.built("caustic_map.vert", "caustic_map.frag", {});  // built now: a compile error comes with the renderer
  programs_.built("caustic_splat.vert", "caustic_splat.frag", {});
}

CausticPass::~CausticPass() {
  for (unsigned t : {maps_, photon_tex_[0], photon_tex_[1], photon_tex_[2]})
    if (t) glDeleteTextures(1, &t);
  for (unsigned f : {fbo_, photon_fbo_})
    if (f) glDeleteFramebuffers(1, &f);
  if (empty_vao_) glDeleteVertexArrays(1, &empty_vao_);
}

std::vector<Mat4> CausticPass::elementPoses() const {
  std::vector<Mat4> poses;
  for (const Element& el : scene_.elements) poses.push_back(el.local_to_world);
  return poses;
}

void CausticPass::update(FrameStages& stages) {
  if (!active()) {
    stages.skipped(kCausticMapsStage, "no light has \"caustics\": true");
    return;
  }
  if (scene_.elements.empty()) {
    stages.skipped(kCausticMapsStage, "the scene has no mirror or lens");
    return;
  }
  if (rendered_ && elementPoses() == rendered_poses_ && scene_.mesh_motion == rendered_mesh_motion_) {
    stages.ran(kCausticMapsStage, 0, 0, "reused: the lights, the elements and the animated meshes stood still");
    return;
  }
  const auto t0 = Clock::now();
  CausticPlanOptions o;
  o.dispersion = scene_.render.dispersion;
  o.spectral_samples = scene_.render.spectral_samples;
  plan_ = planCaustics(rays_, o);
  rendered_poses_ = elementPoses();
  rendered_mesh_motion_ = scene_.mesh_motion;
  rendered_ = true;
  if (plan_.receivers.empty()) {
    std::string why = "no caustic light lands on a planar or height-field receiver";
    for (const std::string& n : plan_.notes) why += "; " + n;
    stages.skipped(kCausticMapsStage, why);
    return;
  }
  render();
  stages.ran(kCausticMapsStage, msSince(t0), int(plan_.receivers.size()), planNote(plan_, map_size_));
}

void CausticPass::render() {
  GLint previous_fbo = 0, viewport[4];
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous_fbo);
  glGetIntegerv(GL_VIEWPORT, viewport);
  // The receivers' light maps: one layer each, cleared.
  cells_side_ = 0;
  for (const CausticReceiver& r : plan_.receivers)
    cells_side_ = std::max({cells_side_, r.window.cells_u, r.window.cells_v});
  if (!maps_) glGenTextures(1, &maps_);
  glBindTexture(GL_TEXTURE_2D_ARRAY, maps_);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA32F, cells_side_, cells_side_, GLsizei(plan_.receivers.size()), 0,
               GL_RGBA, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  if (!fbo_) glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glDrawBuffer(GL_COLOR_ATTACHMENT0);
  glClearColor(0, 0, 0, 0);
  for (size_t r = 0; r < plan_.receivers.size(); ++r) {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, maps_, 0, GLint(r));
    glClear(GL_COLOR_BUFFER_BIT);
  }
  // A curved receiver's layer holds the surface's height over its plane in alpha (the lookup's test of whether a
  // point lies on it); the splat adds 0 there. Cells beyond its window: kNoHeight.
  for (size_t r = 0; r < plan_.receivers.size(); ++r) {
    const CausticReceiver& rec = plan_.receivers[r];
    if (!rec.curved) continue;
    std::vector<float> texels(size_t(cells_side_) * size_t(cells_side_) * 4, 0.0f);
    for (int j = 0; j < cells_side_; ++j)
      for (int i = 0; i < cells_side_; ++i)
        texels[(size_t(j) * size_t(cells_side_) + size_t(i)) * 4 + 3] =
            i < rec.window.cells_u && j < rec.window.cells_v ? rec.height[size_t(j) * size_t(rec.window.cells_u) + size_t(i)]
                                                             : kNoHeight;
    glBindTexture(GL_TEXTURE_2D_ARRAY, maps_);
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, GLint(r), cells_side_, cells_side_, 1, GL_RGBA, GL_FLOAT,
                    texels.data());
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  }
  // The photon maps: exit origin, direction and power per texel.
  if (!photon_fbo_) {
    glGenFramebuffers(1, &photon_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, photon_fbo_);
    for (int k = 0; k < 3; ++k) {
      makeTexture2D(photon_tex_[k], map_size_, map_size_);
      glFramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + k), GL_TEXTURE_2D, photon_tex_[k], 0);
    }
    glGenVertexArrays(1, &empty_vao_);
  }
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  for (const CausticMesh& m : plan_.meshes) splat(m);
  glDisable(GL_BLEND);
  glDisable(GL_PROGRAM_POINT_SIZE);
  glDepthMask(GL_TRUE);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous_fbo));
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  checkGlError("rendering the caustic maps");
}

// One photon mesh: its caustic map, then its photons into each receiver's light map.
void CausticPass::splat(const CausticMesh& m) {
  const CausticAperture& ap = m.aperture;
  // A curved receiver's plane normal per surface (CausticVertex::surface): its photons' power is weighed by
  // cos(theta) between the hit's normal and that plane's (irradiance per unit area of the surface, as
  // DepositOptions::height_field).
  std::vector<const ReceiverRect*> curved;
  for (const CausticReceiver& r : plan_.receivers)
    if (r.curved) {
      if (curved.size() <= size_t(r.surface)) curved.resize(size_t(r.surface) + 1, nullptr);
      curved[size_t(r.surface)] = &r.full;
    }
  std::vector<float> data;
  data.reserve(m.vertices.size() * 13);
  for (const CausticVertex& v : m.vertices) {
    const Vec3 o = v.origin - m.anchor;
    const ReceiverRect* c = v.surface >= 0 && size_t(v.surface) < curved.size() ? curved[size_t(v.surface)] : nullptr;
    const Vec3 power = c ? v.power_density * std::abs(glm::dot(v.hit_normal, c->normal())) : v.power_density;
    data.insert(data.end(),
                {float(2 * (v.xy.x - ap.x0) / (ap.x1 - ap.x0) - 1), float(2 * (v.xy.y - ap.y0) / (ap.y1 - ap.y0) - 1),
                 float(o.x), float(o.y), float(o.z), float(v.direction.x), float(v.direction.y), float(v.direction.z),
                 float(power.x), float(power.y), float(power.z), float(v.surface), float(v.t_hit)});
  }
  MeshBuffers mesh;
  uploadMesh(mesh, data, {2, 3, 3, 3, 1, 1}, m.triangles);
  glBindFramebuffer(GL_FRAMEBUFFER, photon_fbo_);
  const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glDrawBuffers(3, buffers);
  glViewport(0, 0, map_size_, map_size_);
  glDisable(GL_BLEND);
  glClearColor(0, 0, 0, 0);
  glClear(GL_COLOR_BUFFER_BIT);
  programs_.built("caustic_map.vert", "caustic_map.frag", {}).use();
  draw(mesh);
  mesh.release();

  const Program& p = programs_.built("caustic_splat.vert", "caustic_splat.frag", {});
  p.use();
  for (int k = 0; k < 3; ++k) {
    glActiveTexture(GLenum(GL_TEXTURE0 + k));
    glBindTexture(GL_TEXTURE_2D, photon_tex_[k]);
  }
  glActiveTexture(GL_TEXTURE0);
  p.set("u_origin", 0);
  p.set("u_direction", 1);
  p.set("u_power", 2);
  p.set("u_side", map_size_);
  p.set("u_texel_measure", float((ap.x1 - ap.x0) * (ap.y1 - ap.y0) / (double(map_size_) * map_size_)));
  p.set("u_receivers", int(plan_.receivers.size()));
  for (size_t r = 0; r < plan_.receivers.size(); ++r) {
    const ReceiverRect& full = plan_.receivers[r].full;
    const std::string k = "[" + std::to_string(r) + "]";
    p.set("u_centre" + k, glm::vec3(full.centre - m.anchor));
    p.set("u_axis_u" + k, glm::vec3(full.u_axis));
    p.set("u_axis_v" + k, glm::vec3(full.v_axis));
    p.set("u_half" + k, glm::vec2(0.5 * full.width_m, 0.5 * full.height_m));
    p.set("u_mesh" + k, plan_.receivers[r].surface);
    p.set("u_curved" + k, plan_.receivers[r].curved ? 1 : 0);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glDrawBuffer(GL_COLOR_ATTACHMENT0);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glBindVertexArray(empty_vao_);
  for (size_t r = 0; r < plan_.receivers.size(); ++r) {
    const CausticReceiver& rec = plan_.receivers[r];
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, maps_, 0, GLint(r));
    glViewport(0, 0, rec.window.cells_u, rec.window.cells_v);
    p.set("u_receiver", int(r));
    p.set("u_window_centre", glm::vec2(rec.full.toReceiver(rec.window.centre)));
    p.set("u_window_size", glm::vec2(rec.window.width_m, rec.window.height_m));
    p.set("u_cells", glm::vec2(rec.window.cells_u, rec.window.cells_v));
    p.set("u_inv_cell_area", float(1.0 / rec.window.cellArea()));
    glDrawArrays(GL_POINTS, 0, GLsizei(map_size_) * map_size_);
  }
}

void CausticPass::bind(const Program& p, const Vec3& origin) const {
  if (!active()) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + unit_));
  glBindTexture(GL_TEXTURE_2D_ARRAY, maps_);
  glActiveTexture(GL_TEXTURE0);
  p.set("u_caustic_map", unit_);
  const int count = maps_ ? int(plan_.receivers.size()) : 0;
  p.set("u_caustic_count", count);
  for (int r = 0; r < count; ++r) {
    const ReceiverRect& w = plan_.receivers[size_t(r)].window;
    const std::string k = "[" + std::to_string(r) + "]";
    const double side = cells_side_;
    p.set("u_caustic_centre" + k, glm::vec3(w.centre - origin));
    p.set("u_caustic_u" + k, glm::vec3(w.u_axis));
    p.set("u_caustic_v" + k, glm::vec3(w.v_axis));
    p.set("u_caustic_scale" + k, glm::vec4(float(w.cells_u / w.width_m / side), float(w.cells_v / w.height_m / side),
                                           float(0.5 * w.cells_u / side), float(0.5 * w.cells_v / side)));
    p.set("u_caustic_extent" + k, glm::vec2(float(w.cells_u / side), float(w.cells_v / side)));
  }
}

std::vector<CausticMap> CausticPass::readMaps() const {
  std::vector<CausticMap> out;
  if (!maps_ || plan_.receivers.empty()) return out;
  const size_t layer = size_t(cells_side_) * size_t(cells_side_) * 4;
  std::vector<float> all(layer * plan_.receivers.size());
  glBindTexture(GL_TEXTURE_2D_ARRAY, maps_);
  glGetTexImage(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA, GL_FLOAT, all.data());
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  checkGlError("reading the caustic maps");
  for (size_t r = 0; r < plan_.receivers.size(); ++r) {
    CausticMap m;
    m.mesh = plan_.receivers[r].mesh;
    m.grid = IrradianceGrid::zeros(plan_.receivers[r].window);
    m.height = plan_.receivers[r].height;
    m.sheet = plan_.receivers[r].sheet;
    for (int j = 0; j < m.grid.rect.cells_v; ++j)
      for (int i = 0; i < m.grid.rect.cells_u; ++i) {
        const float* t = &all[r * layer + (size_t(j) * size_t(cells_side_) + size_t(i)) * 4];
        m.grid.irradiance[m.grid.index(i, j)] = Vec3(t[0], t[1], t[2]);
      }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace pvrr::gl

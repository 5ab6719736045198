#include "pvrr/gl/impostor_maps.h"

#include <algorithm>
#include <string>

#include "pvrr/gl/gl.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr::gl {

ImpostorMaps::~ImpostorMaps() {
  for (LensMaps& m : lens_maps)
    for (GLuint t : {m.front, m.back, m.mask})
      if (t) glDeleteTextures(1, &t);
  for (MirrorMaps& m : mirror_maps)
    for (GLuint t : m.textures)
      if (t) glDeleteTextures(1, &t);
}

int ImpostorMaps::updateLensMaps(size_t e) {
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

int ImpostorMaps::updateMirrorMaps(size_t e) {
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

void ImpostorMaps::setMirrorMaps(const Program& p, size_t e) const {
  const MirrorMaps& m = mirror_maps.at(e);
  static_assert(kSurfaceMapUnits == 4, "the four surface maps below");
  bindDataTextures(p, kElementMapsUnit,
                   {{"u_surf_p", m.textures[0]},
                    {"u_surf_du", m.textures[1]},
                    {"u_surf_dv", m.textures[2]},
                    {"u_surf_n", m.textures[3]}});
  const double n = m.map.n;
  p.set("u_sm", glm::vec2(float((n - 1) / n), float(0.5 / n)));
  p.set("u_to_local", glm::mat3(Mat3(scene.elements[e].world_to_local)));
}

void ImpostorMaps::setLensMaps(const Program& p, size_t e, int first_unit, const char* rotation) const {
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
  p.set("u_absorption", glm::vec3(el.absorption_per_m));  // a tinted lens (lens_march.glsl throughLens)
  p.set("u_index", glm::vec3(float(el.dispersion.index(wl[0])), float(el.dispersion.index(wl[1])),
                             float(el.dispersion.index(wl[2]))));
}

size_t ImpostorMaps::lensCount() const {
  return size_t(std::count_if(scene.elements.begin(), scene.elements.end(),
                              [](const Element& e) { return e.type == ElementType::Lens; }));
}

int ImpostorMaps::cubeElements(RenderMode mode) const {
  const int n = int(scene.elements.size());
  const bool mirror = lensCount() < size_t(n);
  // Three cubes per element, and the lens's three height maps for the mirrors that meet it.
  if (mode != RenderMode::Impostor || n < 2 || !mirror || n > kMaxCubeElements ||
      kFirstCubeUnit + 3 * n + (lensCount() == 1 ? 3 : 0) > max_texture_units)
    return 0;
  return n;
}

int ImpostorMaps::impostorLayers(RenderMode mode) const {
  if (mode != RenderMode::Impostor || scene.render.impostor_layers < 2) return 1;
  const int follow = cubeElements(mode);
  const int units = follow > 0 ? kFirstCubeUnit + 6 * follow + (lensCount() == 1 ? 3 : 0) : kFirstCubeUnit + 2;
  return units <= max_texture_units ? 2 : 1;
}

int ImpostorMaps::impostorChannels(size_t e) const {
  auto dispersive = [&](size_t k) { return dispersionChannels(scene, int(k)).size() > 1; };
  if (scene.elements[e].type == ElementType::Lens) return dispersive(e) ? 3 : 1;
  if (!lensInCubes(RenderMode::Impostor)) return 1;
  for (size_t k = 0; k < scene.elements.size(); ++k)
    if (scene.elements[k].type == ElementType::Lens && dispersive(k)) return 3;
  return 1;
}

void ImpostorMaps::setCubeElements(const Program& p, size_t e, const Vec3& origin, int layers,
                                   const std::vector<std::unique_ptr<CubeTarget>>& cubes,
                                   const std::vector<std::unique_ptr<CubeTarget>>& cubes1) const {
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

}  // namespace pvrr::gl

#include "pvrr/vertex_stage.h"

#include <tbb/parallel_for.h>

#include <chrono>

#include "cad/error.h"
#include "pvrr/optics.h"

namespace pvrr {

const char* toString(VertexStatus s) {
  switch (s) {
    case VertexStatus::Hit: return "hit";
    case VertexStatus::Escape: return "escape";
    case VertexStatus::Tir: return "tir";
  }
  return "?";
}

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

ElementFrame prepareElement(const Scene& scene, int element) {
  const Element& el = scene.elements[size_t(element)];
  ElementFrame f;
  f.element = element;
  f.grid = cad::tessellateGrid(el.frontSurface(), el.tess_u, el.tess_v, el.has_outline ? &el.outline : nullptr,
                               cad::TessellationOptions{true});
  f.world_pos.resize(f.grid.vertexCount());
  f.world_normal.resize(f.grid.vertexCount());
  for (size_t i = 0; i < f.grid.vertexCount(); ++i) {
    f.world_pos[i] = el.toWorldPoint(f.grid.positions[i]);
    f.world_normal[i] = glm::normalize(el.toWorldDir(f.grid.normals[i]));
  }
  f.patches_u = el.patches_u;
  f.patches_v = el.patches_v;
  return f;
}

void traceVertexRays(const RayScene& rays, ElementFrame& f, const Vec3& eye, const VertexStageOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  const Scene& scene = rays.scene();
  const Element& el = scene.elements[size_t(f.element)];
  const double eps = rays.epsilon();
  const double far = scene.render.far_distance_m;
  f.eye = eye;
  f.rays.assign(opt.channels.size(), std::vector<VertexRay>(f.world_pos.size()));
  for (size_t c = 0; c < opt.channels.size(); ++c) {
    const double wl = opt.channels[c].wavelength_nm > 0 ? opt.channels[c].wavelength_nm : kLineD_nm;
    // Vertices are independent: one task per block of vertices.
    tbb::parallel_for(size_t(0), f.world_pos.size(), [&](size_t i) {
      VertexRay& vr = f.rays[c][i];
      const Vec3 p = f.world_pos[i], n = f.world_normal[i];
      const Vec3 d_in = glm::normalize(p - eye);
      if (el.type == ElementType::Mirror) {
        vr.origin = p;
        vr.dir = reflect(d_in, n);
      } else {
        const double n_glass = el.dispersion.index(wl);
        Refraction in = refract(d_in, n, 1.0, n_glass);
        if (in.tir) {  // cannot happen entering from air; kept for completeness
          vr.status = VertexStatus::Tir;
          vr.origin = p;
          vr.dir = d_in;
          vr.hit = p + far * d_in;
          return;
        }
        vr.internal_dir = in.direction;
        RayHit back = rays.intersectElementSurface(f.element, 1, p, in.direction, eps);
        if (!back.hit()) {
          // The internal ray leaves through the edge band: no back point. Treated like TIR: flagged.
          vr.status = VertexStatus::Tir;
          vr.origin = p;
          vr.dir = in.direction;
          vr.hit = p + far * in.direction;
          return;
        }
        vr.back_point = back.point;
        vr.back_normal = back.normal;
        Refraction out = refract(in.direction, back.normal, n_glass, 1.0);
        const double cos_in = std::abs(glm::dot(d_in, n));
        const double cos_back = std::abs(glm::dot(in.direction, back.normal));
        const double trans = (1.0 - fresnelDielectric(cos_in, 1.0, n_glass)) *
                             (out.tir ? 0.0 : 1.0 - fresnelDielectric(cos_back, n_glass, 1.0));
        vr.transmittance = Vec3(trans);
        vr.origin = back.point;
        if (out.tir) {
          vr.status = VertexStatus::Tir;
          vr.dir = reflect(in.direction, back.normal);
          vr.hit = back.point + far * vr.dir;
          return;
        }
        vr.dir = out.direction;
      }
      RayHit h = rays.intersect(vr.origin, vr.dir, eps);
      if (h.hit()) {
        vr.status = VertexStatus::Hit;
        vr.hit = h.point;
      } else {
        vr.status = VertexStatus::Escape;
        vr.hit = vr.origin + far * vr.dir;
      }
    });
  }
  f.rays_ms = msSince(t0);
}

namespace {

void fitOnePatch(const Scene& scene, const ElementFrame& f, size_t patch_index, const Element& el,
                 PatchView& pv, const ViewpointOptions& vopt) {
  const cad::GridPatch& gp = f.grid_patches[patch_index];
  const size_t channels = f.rays.size();
  const size_t fit_channel = channels / 2;  // the middle (green) channel, or the only one
  pv.patch = int(patch_index);
  std::vector<ViewpointRay> vrays, fit_rays;
  vrays.reserve(gp.vertices.size());
  for (uint32_t vi : gp.vertices) {
    const VertexRay& r = f.rays[fit_channel][vi];
    vrays.push_back(ViewpointRay{r.origin, r.dir, r.hit});
    // A ray that never left the lens properly (TIR, or out through the edge band) says nothing about where
    // the scene is seen from: keep it out of the fit.
    if (r.status != VertexStatus::Tir) fit_rays.push_back(vrays.back());
  }
  pv.rays_excluded = int(vrays.size() - fit_rays.size());
  if (fit_rays.size() < 3) fit_rays = vrays;
  pv.fit = fitViewpoint(fit_rays, vopt);
  ViewVolumeOptions vo;
  vo.scene_radius_m = scene.boundsRadius();
  vo.scene_center = 0.5 * (scene.bounds_min + scene.bounds_max);
  // Saddle and cylindrical surfaces: align the map's up vector with a principal direction (paper 4.3).
  const size_t centre_vertex = gp.vertices[gp.vertices.size() / 2];
  if (!f.grid.curvatures.empty()) {
    const cad::Curvature& k = f.grid.curvatures[centre_vertex];
    if (k.k1 * k.k2 < 0 || std::abs(k.k2) < 1e-3 * std::abs(k.k1)) {
      vo.up_hint = glm::normalize(el.toWorldDir(k.dir2));
    }
  }
  pv.volume = buildViewVolume(pv.fit.eye, fit_rays, vo);
  // Concave mirrors and convex lenses: when most hits lie between the surface and the viewpoint (the
  // zooming region), render the map looking back from the viewpoint with a reversed depth test (paper's
  // future work). A patch with both kinds keeps the majority's volume and reports the rest.
  const size_t zooming = pv.volume.zooming.size();
  if (2 * zooming > fit_rays.size()) {
    const std::string forward_note = pv.volume.note;
    pv.volume = buildReversedViewVolume(pv.fit.eye, fit_rays, vo);
    if (zooming < fit_rays.size())
      pv.volume.note += (pv.volume.note.empty() ? "" : "; ") + std::to_string(fit_rays.size() - zooming) +
                        " hit(s) beyond the viewpoint are not in this reversed map";
  }
  pv.q.assign(gp.vertices.size(), 1.0);
  bool all_in_front = true;
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    const Vec4 clip = pv.volume.projection * pv.volume.view * Vec4(f.world_pos[gp.vertices[k]], 1.0);
    pv.q[k] = clip.w;
    all_in_front = all_in_front && clip.w > 0;
  }
  if (!all_in_front) pv.q.assign(gp.vertices.size(), 1.0);
  pv.st.assign(channels, std::vector<Vec2>(gp.vertices.size()));
  for (size_t c = 0; c < channels; ++c)
    for (size_t k = 0; k < gp.vertices.size(); ++k)
      pv.st[c][k] = projectToTexture(pv.volume, f.rays[c][gp.vertices[k]].hit);
}

}  // namespace

void fitPatchViews(const Scene& scene, ElementFrame& f, const VertexStageOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  const Element& el = scene.elements[size_t(f.element)];
  const double max_fov = opt.max_patch_fov_rad > 0 ? opt.max_patch_fov_rad : el.max_patch_fov_rad;
  int pu = el.patches_u, pv = el.patches_v;
  f.split_note.clear();
  for (int round = 0;; ++round) {
    f.grid_patches = cad::splitGrid(f.grid, pu, pv);
    f.views.clear();
    f.views.resize(f.grid_patches.size());
    for (size_t p = 0; p < f.grid_patches.size(); ++p) fitOnePatch(scene, f, p, el, f.views[p], opt.viewpoint);
    if (max_fov <= 0 || round >= opt.max_patch_splits) break;
    double worst_x = 0, worst_y = 0;
    for (const PatchView& v : f.views) {
      worst_x = std::max(worst_x, v.volume.fov_x_rad);
      worst_y = std::max(worst_y, v.volume.fov_y_rad);
    }
    if (std::max(worst_x, worst_y) <= max_fov) break;
    // Split along the grid direction whose patches still have room, both when both exceed.
    const int next_u = std::min(pu * 2, f.grid.grid_u - 1), next_v = std::min(pv * 2, f.grid.grid_v - 1);
    if (next_u == pu && next_v == pv) {
      f.split_note = "patch field of view still above the threshold at the finest split the grid allows";
      break;
    }
    f.split_note = "split to " + std::to_string(next_u) + "x" + std::to_string(next_v) +
                   " patches: a view volume's field of view exceeded " + std::to_string(degrees(max_fov)) + " deg";
    pu = next_u;
    pv = next_v;
  }
  f.patches_u = pu;
  f.patches_v = pv;
  f.fit_ms = msSince(t0);
}

}  // namespace pvrr

// View volumes of the reflection map (paper 3.3; reversed volume for the zooming region, paper 4.2 and 7).
#include "pvrr/method/view_volume.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pvrr/base/error.h"
#include "pvrr/base/format.h"

namespace pvrr {
namespace {

void validate(const char* who, const Vec3& eye, const std::vector<ViewpointRay>& rays) {
  if (rays.empty()) throw Error(std::string(who) + ": no rays given; expected the vertex rays of a patch");
  if (!isFinite(eye)) throw Error(std::string(who) + ": the eye is not finite");
  for (size_t i = 0; i < rays.size(); ++i) {
    const double len = glm::length(rays[i].direction);
    if (!isFinite(rays[i].origin) || !isFinite(rays[i].hit) || !std::isfinite(len) || !(len > 0))
      throw Error(std::string(who) + ": ray " + std::to_string(i) +
                  ": expected a finite origin and hit point and a non-zero finite direction");
  }
}

// Normalised mean of the directions of rays[idx] (all rays when idx is null).
Vec3 meanDirection(const char* who, const std::vector<ViewpointRay>& rays, const std::vector<int>* idx) {
  Vec3 sum(0);
  size_t n = 0;
  auto add = [&](size_t i) { sum += glm::normalize(rays[i].direction), ++n; };
  if (idx)
    for (int i : *idx) add(size_t(i));
  else
    for (size_t i = 0; i < rays.size(); ++i) add(i);
  const double len = glm::length(sum);
  if (!(len > 1e-6 * double(n)))
    throw Error(std::string(who) + ": the ray directions cancel out (mean length " + fmt("%.3g", len / double(n)) +
                "); no single view volume can contain them: split the patch (paper 4.1)");
  return sum / len;
}

// Rays whose hit lies at or behind the eye along the patch's mean direction.
std::vector<int> zoomingRays(const Vec3& eye, const std::vector<ViewpointRay>& rays, const Vec3& forward) {
  std::vector<int> out;
  for (size_t i = 0; i < rays.size(); ++i)
    if (glm::dot(rays[i].hit - eye, forward) <= 0) out.push_back(int(i));
  return out;
}

// up perpendicular to forward: hint, else world up, else the world axis least aligned with forward.
Vec3 chooseUp(const Vec3& forward, const ViewVolumeOptions& opt, std::string& note) {
  auto perp = [&](const Vec3& v) -> std::optional<Vec3> {
    const double len = glm::length(v);
    if (!(len > 0) || !std::isfinite(len)) return std::nullopt;
    const Vec3 w = v / len;
    const Vec3 p = w - glm::dot(w, forward) * forward;
    const double plen = glm::length(p);
    if (!(plen > 1e-6)) return std::nullopt;  // within 0.06 mrad of forward: no usable direction
    return p / plen;
  };
  if (opt.up_hint) {
    if (auto u = perp(*opt.up_hint)) return *u;
    appendNote(note, "up hint is parallel to forward; used world up");
  }
  if (auto u = perp(opt.world_up)) return *u;
  const Vec3 a = glm::abs(forward);
  const Vec3 axis = a.x <= a.y && a.x <= a.z ? Vec3(1, 0, 0) : (a.y <= a.z ? Vec3(0, 1, 0) : Vec3(0, 0, 1));
  appendNote(note, "world up is parallel to forward; up from the least aligned world axis");
  return *perp(axis);
}

// Frame, matrices and angles from eye, forward, up, near, far and the extents already set in vv.
void finish(ViewVolume& vv) {
  const Vec3 &r = vv.right, &u = vv.up, &f = vv.forward;
  Mat4 R(1.0);
  for (int c = 0; c < 3; ++c) {
    R[c][0] = r[c];
    R[c][1] = u[c];
    R[c][2] = -f[c];
  }
  vv.view_relative = R;
  vv.view = R;
  vv.view[3][0] = -glm::dot(r, vv.eye);
  vv.view[3][1] = -glm::dot(u, vv.eye);
  vv.view[3][2] = glm::dot(f, vv.eye);
  // glFrustum(left, right, bottom, top, near, far).
  const double l = vv.left, rr = vv.right_, b = vv.bottom, t = vv.top, n = vv.near_m, fa = vv.far_m;
  Mat4 P(0.0);
  P[0][0] = 2 * n / (rr - l);
  P[1][1] = 2 * n / (t - b);
  P[2][0] = (rr + l) / (rr - l);
  P[2][1] = (t + b) / (t - b);
  P[2][2] = -(fa + n) / (fa - n);
  P[2][3] = -1;
  P[3][2] = -2 * fa * n / (fa - n);
  vv.projection = P;
  vv.fov_x_rad = std::atan(rr / n) - std::atan(l / n);
  vv.fov_y_rad = std::atan(t / n) - std::atan(b / n);
}

// Sides from the segments [a_i, b_i] clipped to near <= z <= far; margin; fov limit; hits_outside.
void fitSides(ViewVolume& vv, const std::vector<std::pair<Vec3, Vec3>>& segments, const std::vector<Vec3>& hits,
              const ViewVolumeOptions& opt) {
  double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
  auto addPoint = [&](const Vec3& p) {
    const Vec3 v = p - vv.eye;
    const double z = glm::dot(v, vv.forward);
    const double x = vv.near_m * glm::dot(v, vv.right) / z, y = vv.near_m * glm::dot(v, vv.up) / z;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };
  for (const auto& [a, b] : segments) {
    const double za = glm::dot(a - vv.eye, vv.forward), zb = glm::dot(b - vv.eye, vv.forward);
    // Parameter interval of a + s (b - a), s in [0, 1], with near <= z <= far.
    double s0 = 0, s1 = 1;
    const double dz = zb - za;
    if (dz != 0) {
      double sn = (vv.near_m - za) / dz, sf = (vv.far_m - za) / dz;
      if (sn > sf) std::swap(sn, sf);
      s0 = std::max(s0, sn), s1 = std::min(s1, sf);
    } else if (za < vv.near_m || za > vv.far_m) {
      continue;
    }
    if (s0 > s1) continue;
    addPoint(a + s0 * (b - a));
    addPoint(a + s1 * (b - a));
  }
  if (!(x0 <= x1 && y0 <= y1)) {  // nothing to contain: a nominal 90 deg square
    x0 = y0 = -vv.near_m, x1 = y1 = vv.near_m;
  }
  // A single point (one ray) has no extent: give it 1e-6 of near (0.06 mrad) so the matrix stays regular.
  const double min_size = 1e-6 * vv.near_m;
  if (x1 - x0 < min_size) x0 -= 0.5 * min_size, x1 += 0.5 * min_size;
  if (y1 - y0 < min_size) y0 -= 0.5 * min_size, y1 += 0.5 * min_size;
  const double w = x1 - x0, h = y1 - y0;
  x0 -= opt.margin * w, x1 += opt.margin * w, y0 -= opt.margin * h, y1 += opt.margin * h;
  const double lim = vv.near_m * std::tan(0.5 * std::min(opt.max_fov_rad, kPi - 1e-6));
  bool clamped = false;
  if (x0 < -lim) x0 = -lim, clamped = true;
  if (x1 > lim) x1 = lim, clamped = true;
  if (y0 < -lim) y0 = -lim, clamped = true;
  if (y1 > lim) y1 = lim, clamped = true;
  vv.left = x0, vv.right_ = x1, vv.bottom = y0, vv.top = y1;
  finish(vv);
  vv.hits_covered = int(hits.size());
  for (const Vec3& p : hits) {
    const Vec2 st = projectToTexture(vv, p);
    if (!(st.x >= 0 && st.x <= 1 && st.y >= 0 && st.y <= 1)) ++vv.hits_outside;
  }
  if (clamped)
    appendNote(vv.note, "frustum limited to max_fov " + fmt("%.4g", degrees(opt.max_fov_rad)) + " deg: " +
                            std::to_string(vv.hits_outside) + " hit point(s) project outside the map; split "
                            "the patch (paper 4.1)");
}

}  // namespace

// The clip plane of a forward volume whose near plane could not clip the mirror (ViewVolume::clip_plane): the
// plane of the three ray origins spanning the largest triangle (found greedily: the origin farthest from the
// first, the one farthest from that, the one farthest from their line), turned so that the hits lie on its
// positive side, moved to the rearmost origin less 1e-6 of the origins' extent (float rounding on the GPU).
// None when the origins are (nearly) collinear or some hit of this volume is not beyond every origin. Every
// vertex ray's segment [origin, hit] then lies on the kept side: the plane clips nothing a vertex ray meets.
static std::optional<Vec4> separatingPlane(const std::vector<ViewpointRay>& rays, const std::vector<char>& is_zoom) {
  if (rays.size() < 3) return std::nullopt;
  auto farthestFrom = [&](const Vec3& p) {
    size_t best = 0;
    double d = -1;
    for (size_t i = 0; i < rays.size(); ++i)
      if (glm::length(rays[i].origin - p) > d) d = glm::length(rays[i].origin - p), best = i;
    return best;
  };
  const Vec3 a = rays[farthestFrom(rays[0].origin)].origin, b = rays[farthestFrom(a)].origin;
  Vec3 n(0.0);
  for (const ViewpointRay& r : rays) {
    const Vec3 c = glm::cross(b - a, r.origin - a);
    if (glm::length(c) > glm::length(n)) n = c;
  }
  const double ab = glm::length(b - a);
  if (!(ab > 0) || !(glm::length(n) > 1e-6 * ab * ab)) return std::nullopt;
  n = glm::normalize(n);
  double towards = 0;
  for (size_t i = 0; i < rays.size(); ++i)
    if (!is_zoom[i]) towards += glm::dot(n, rays[i].hit - rays[i].origin);
  if (towards < 0) n = -n;
  double o_min = kInf, o_max = -kInf, h_min = kInf;
  for (size_t i = 0; i < rays.size(); ++i) {
    o_min = std::min(o_min, glm::dot(n, rays[i].origin));
    o_max = std::max(o_max, glm::dot(n, rays[i].origin));
    if (!is_zoom[i]) h_min = std::min(h_min, glm::dot(n, rays[i].hit));
  }
  if (!(h_min > o_max) || !std::isfinite(h_min)) return std::nullopt;
  return Vec4(n, -(o_min - 1e-6 * ab));
}

ViewVolume buildViewVolume(const Vec3& eye, const std::vector<ViewpointRay>& rays, const ViewVolumeOptions& opt) {
  validate("buildViewVolume", eye, rays);
  ViewVolume vv;
  vv.eye = eye;
  vv.forward = meanDirection("buildViewVolume", rays, nullptr);
  vv.up = chooseUp(vv.forward, opt, vv.note);
  vv.right = glm::normalize(glm::cross(vv.forward, vv.up));
  vv.up = glm::cross(vv.right, vv.forward);
  vv.zooming = zoomingRays(eye, rays, vv.forward);
  vv.reversed = !vv.zooming.empty();

  std::vector<char> is_zoom(rays.size(), 0);
  for (int i : vv.zooming) is_zoom[size_t(i)] = 1;
  double zo_max = -kInf, zh_min = kInf, zh_max = -kInf;
  std::vector<std::pair<Vec3, Vec3>> segments;
  std::vector<Vec3> hits;
  for (size_t i = 0; i < rays.size(); ++i) {
    zo_max = std::max(zo_max, glm::dot(rays[i].origin - eye, vv.forward));
    if (is_zoom[i]) continue;
    const double zh = glm::dot(rays[i].hit - eye, vv.forward);
    zh_min = std::min(zh_min, zh), zh_max = std::max(zh_max, zh);
    segments.emplace_back(rays[i].origin, rays[i].hit);
    hits.push_back(rays[i].hit);
  }
  if (vv.reversed)
    appendNote(vv.note, std::to_string(vv.zooming.size()) + " hit point(s) lie behind the eye (zooming region): "
                        "not in this volume; render them with buildReversedViewVolume");
  if (hits.empty()) {
    // Nominal volume: 1 m to 2 m, 90 deg.
    vv.near_m = 1, vv.far_m = 2;
    vv.left = vv.bottom = -1, vv.right_ = vv.top = 1;
    finish(vv);
    appendNote(vv.note, "no hit point lies in front of the eye: nominal volume");
    return vv;
  }

  // near: beyond the mirror, before the hits (see header).
  const double near_floor = opt.min_near_fraction * zh_min;
  double near = zo_max + std::min(opt.near_gap_m, 0.5 * (zh_min - zo_max));
  near = std::max(near, near_floor);
  if (!(near < zh_min)) {
    near = (1 - 1e-3) * zh_min;
    for (const ViewpointRay& r : rays)
      if (glm::dot(r.origin - eye, vv.forward) > near) ++vv.mirror_vertices_unclipped;
    appendNote(vv.note, "a hit point is nearer the eye than the farthest mirror vertex (by " +
                            fmt("%.3g", zo_max - zh_min) + " m along forward): near placed just before it, " +
                            std::to_string(vv.mirror_vertices_unclipped) +
                            " mirror vertices not clipped: leave the element out of its own map pass");
    vv.clip_plane = separatingPlane(rays, is_zoom);
    if (vv.clip_plane)
      appendNote(vv.note, "what lies behind the mirror is clipped at a plane just behind it (clip_plane; the "
                          "viewpoint " + fmt("%.3g", -(vv.clip_plane->w + glm::dot(Vec3(*vv.clip_plane), eye))) +
                          " m behind it)");
  }
  double far = zh_max;
  if (opt.scene_radius_m > 0) far = std::max(far, glm::dot(opt.scene_center - eye, vv.forward) + opt.scene_radius_m);
  far *= 1 + opt.far_margin;
  far = std::max(far, near * (1 + 1e-6));
  vv.near_m = near, vv.far_m = far;
  if (far / near > 1e5)
    appendNote(vv.note, "far/near = " + fmt("%.3g", far / near) +
                            ": a 24-bit depth buffer resolves poorly far away (use a float depth buffer)");
  fitSides(vv, segments, hits, opt);
  return vv;
}

ViewVolume buildReversedViewVolume(const Vec3& eye, const std::vector<ViewpointRay>& rays,
                                   const ViewVolumeOptions& opt) {
  validate("buildReversedViewVolume", eye, rays);
  const Vec3 patch_forward = meanDirection("buildReversedViewVolume", rays, nullptr);
  ViewVolume vv;
  vv.eye = eye;
  vv.zooming = zoomingRays(eye, rays, patch_forward);
  if (vv.zooming.empty())
    throw Error("buildReversedViewVolume: no hit point lies behind the eye; no reversed volume is needed");
  vv.backward = true;
  vv.forward = -meanDirection("buildReversedViewVolume", rays, &vv.zooming);
  vv.up = chooseUp(vv.forward, opt, vv.note);
  vv.right = glm::normalize(glm::cross(vv.forward, vv.up));
  vv.up = glm::cross(vv.right, vv.forward);

  // Depths along the backward direction: zooming hits in front, every mirror vertex beyond.
  double zh_min = kInf, zh_max = -kInf, zo_min = kInf;
  std::vector<std::pair<Vec3, Vec3>> segments;
  std::vector<Vec3> hits;
  for (int i : vv.zooming) {
    const double zh = glm::dot(rays[size_t(i)].hit - eye, vv.forward);
    zh_min = std::min(zh_min, zh), zh_max = std::max(zh_max, zh);
    segments.emplace_back(rays[size_t(i)].hit, rays[size_t(i)].origin);
    hits.push_back(rays[size_t(i)].hit);
  }
  for (const ViewpointRay& r : rays) zo_min = std::min(zo_min, glm::dot(r.origin - eye, vv.forward));
  // Zooming hits lie behind the eye along the patch's forward, but the reversed forward is the mean of the
  // zooming rays only: a hit may fall (just) behind this eye plane too.
  if (!(zh_min > 0)) {
    int n_bad = 0;
    for (const Vec3& p : hits) n_bad += glm::dot(p - eye, vv.forward) <= 0;
    appendNote(vv.note, std::to_string(n_bad) + " zooming hit(s) lie beside the eye (depth <= 0 looking back): "
                        "not representable");
    zh_min = kInf;
    for (const Vec3& p : hits) {
      const double z = glm::dot(p - eye, vv.forward);
      if (z > 0) zh_min = std::min(zh_min, z);
    }
    if (!std::isfinite(zh_min)) zh_min = 1e-3 * std::max(zh_max, 1e-3);
  }
  const double near = opt.reversed_near_fraction * zh_min;
  double far = zo_min - std::min(opt.near_gap_m, 0.5 * (zo_min - zh_max));
  if (!(far > zh_max)) {
    far = (1 + 1e-3) * zh_max;
    for (const ViewpointRay& r : rays)
      if (glm::dot(r.origin - eye, vv.forward) < far) ++vv.mirror_vertices_unclipped;
    appendNote(vv.note, "a zooming hit point lies beyond the nearest mirror vertex looking back: far placed just "
                        "beyond it, " + std::to_string(vv.mirror_vertices_unclipped) +
                        " mirror vertices not clipped: leave the element out of this pass");
  }
  far = std::max(far, near * (1 + 1e-6));
  vv.near_m = near, vv.far_m = far;
  appendNote(vv.note, "backward volume: glClearDepth(0), glDepthFunc(GL_GREATER)");
  fitSides(vv, segments, hits, opt);
  return vv;
}

Vec2 projectToTexture(const ViewVolume& vv, const Vec3& p) {
  const Vec3 v = p - vv.eye;
  const double z = glm::dot(v, vv.forward);
  if (!(z > 0)) return Vec2(std::numeric_limits<double>::quiet_NaN());
  const double x = vv.near_m * glm::dot(v, vv.right) / z, y = vv.near_m * glm::dot(v, vv.up) / z;
  return {(x - vv.left) / (vv.right_ - vv.left), (y - vv.bottom) / (vv.top - vv.bottom)};
}

Vec2 projectToTexel(const ViewVolume& vv, const Vec3& p, int width, int height) {
  const Vec2 st = projectToTexture(vv, p);
  return {st.x * width, st.y * height};
}

namespace {
// Width over height of the frustum on its near plane; 1 for a degenerate one.
double frustumAspect(const ViewVolume& vv) {
  const double a = (vv.right_ - vv.left) / (vv.top - vv.bottom);
  return a > 0 && std::isfinite(a) ? a : 1.0;
}
}  // namespace

std::array<int, 2> mapTexels(const ViewVolume& vv, int longest_side) {
  const double a = frustumAspect(vv);
  const int shortest = std::min(longest_side, 16);
  auto share = [&](double ratio) { return std::clamp(int(std::ceil(longest_side * ratio - 1e-9)), shortest, longest_side); };
  return a >= 1 ? std::array<int, 2>{longest_side, share(1 / a)} : std::array<int, 2>{share(a), longest_side};
}

int mapSideForPixels(const ViewVolume& vv, double pixels, double texels_per_pixel, int max_side) {
  if (!(texels_per_pixel > 0) || !(pixels >= 0)) return max_side;
  const double a = frustumAspect(vv), ratio = std::min(a, 1 / a);  // shorter over longer side
  const double side = std::sqrt(texels_per_pixel * pixels / ratio);
  if (!(side < max_side)) return max_side;
  return std::clamp(32 * int(std::ceil(side / 32.0)), std::min(max_side, 128), max_side);
}

ViewVolume widenViewVolume(const ViewVolume& vv, double margin_rad, double max_fov_rad, double far_factor) {
  if (vv.backward) return vv;
  ViewVolume w = vv;
  const double n = vv.near_m, lim = 0.5 * std::min(max_fov_rad, kPi - 1e-6);
  auto side = [&](double extent, double turn) {
    const double a = std::atan(extent / n);
    // A side already beyond the limit (it cannot be: fitSides clamps) stays where it is.
    return n * std::tan(turn < 0 ? std::min(a, std::max(a + turn, -lim)) : std::max(a, std::min(a + turn, lim)));
  };
  w.left = side(vv.left, -margin_rad);
  w.right_ = side(vv.right_, margin_rad);
  w.bottom = side(vv.bottom, -margin_rad);
  w.top = side(vv.top, margin_rad);
  w.far_m = vv.far_m * std::max(1.0, far_factor);
  finish(w);  // hits_outside: vv's count, an upper bound (a side clamped at the limit stays there)
  return w;
}

NearClip::NearClip(const Mat4& view_proj) : view_proj_(view_proj) {
  const Mat4 inv = glm::inverse(view_proj);
  const Vec4 c = inv * Vec4(0, 0, 1, 0);  // the centre of projection: clip x = y = w = 0
  if (!(std::abs(c.w) > 0)) return;
  centre_ = Vec3(c) / c.w;
  double reach = 0;
  for (int k = 0; k < 4; ++k) {
    const Vec4 p = inv * Vec4(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, -1.0, 1.0);
    reach = std::max(reach, glm::length(Vec3(p) / p.w - centre_));
  }
  if (isFinite(centre_) && std::isfinite(reach)) reach_ = reach;
}

bool NearClip::cannotOpen(const Vec3& lo, const Vec3& hi) const {
  const double size = glm::length(hi - lo) + std::max(glm::length(lo), glm::length(hi));
  bool beyond = true;
  for (int c = 0; c < 8 && beyond; ++c) {
    const Vec4 p = view_proj_ * Vec4(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z, 1.0);
    beyond = p.z + p.w > 1e-6 * (std::abs(p.w) + size);
  }
  if (beyond) return true;
  if (reach_ < 0) return false;
  const double gap = glm::length(glm::max(glm::max(lo - centre_, centre_ - hi), Vec3(0.0)));
  return gap > reach_ * (1 + 1e-6) + 1e-6 * size;
}

std::vector<size_t> depthSortedDrawOrder(const std::vector<std::array<Vec3, 2>>& boxes, bool reversed_depth) {
  std::vector<std::pair<double, size_t>> key(boxes.size());
  for (size_t m = 0; m < boxes.size(); ++m) {
    const Vec3 &lo = boxes[m][0], &hi = boxes[m][1];
    // A box around the centre: the distance to its nearest face, where a room that is its box has its
    // nearest wall (an ordering heuristic: a mesh inside the box may come closer).
    const bool around = glm::all(glm::lessThanEqual(lo, Vec3(0.0))) && glm::all(glm::greaterThanEqual(hi, Vec3(0.0)));
    const double nearest = around ? std::min({-lo.x, -lo.y, -lo.z, hi.x, hi.y, hi.z})
                                  : glm::length(glm::clamp(Vec3(0.0), lo, hi));
    key[m] = {reversed_depth ? -glm::length(glm::max(glm::abs(lo), glm::abs(hi))) : nearest, m};
  }
  std::stable_sort(key.begin(), key.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<size_t> order(key.size());
  for (size_t i = 0; i < key.size(); ++i) order[i] = key[i].second;
  return order;
}

// A triangle counter-clockwise in NDC (x right, y up, as window space), unprojected onto the plane z_ndc = 0,
// and a point unprojected from z_ndc = -1/2. Along every ray from the centre of projection z_ndc rises from
// -infinity, so that point lies on the centre's side of the plane: the triangle faces the centre exactly
// when its counter-clockwise normal points to that side.
bool facingTrianglesWindCounterClockwise(const Mat4& view_proj) {
  const Mat4 inv = glm::inverse(view_proj);
  auto unproject = [&](double x, double y, double z) {
    const Vec4 p = inv * Vec4(x, y, z, 1.0);
    return Vec3(p) / p.w;
  };
  const Vec3 a = unproject(0, 0, 0), b = unproject(0.5, 0, 0), c = unproject(0, 0.5, 0);
  const Vec3 centre_side = unproject(0, 0, -0.5);
  return glm::dot(glm::cross(b - a, c - a), centre_side - a) > 0;
}

bool frustumContains(const ViewVolume& outer, const ViewVolume& inner) {
  const Mat4 clip = outer.projection * outer.view;
  for (int k = 0; k < 8; ++k) {
    const bool far = k & 4;
    const double d = far ? inner.far_m : inner.near_m, s = d / inner.near_m;
    const double x = s * ((k & 1) ? inner.right_ : inner.left), y = s * ((k & 2) ? inner.top : inner.bottom);
    const Vec3 p = inner.eye + d * inner.forward + x * inner.right + y * inner.up;
    const Vec4 c = clip * Vec4(p, 1.0);
    if (!(c.w > 0) || std::abs(c.x) > c.w || std::abs(c.y) > c.w || (far && c.z > c.w)) return false;
  }
  return true;
}

double longerExtentTan(const ViewVolume& vv) {
  return std::max(vv.right_ - vv.left, vv.top - vv.bottom) / vv.near_m;
}

double minTexelAngle(const ViewVolume& vv, int longest_side) {
  const double tx = std::max(std::abs(vv.left), std::abs(vv.right_)) / vv.near_m,
               ty = std::max(std::abs(vv.bottom), std::abs(vv.top)) / vv.near_m;
  return longerExtentTan(vv) / std::max(1, longest_side) / (1 + tx * tx + ty * ty);
}

std::array<double, 16> rowMajor16(const Mat4& m) {
  std::array<double, 16> out{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[size_t(4 * r + c)] = m[c][r];
  return out;
}

}  // namespace pvrr

#include "pvrr/trace/ray_scene.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

#include "pvrr/base/error.h"
#include "cad/sag.h"

namespace pvrr {

namespace {

// Candidate vertices per bounding box in RayScene::tangentClearance.
constexpr size_t kClearanceChunk = 32;

void embreeError(void*, RTCError code, const char* message) {
  // Errors reach us through rtcGetDeviceError checks below; keep a trace on stderr for diagnosis.
  std::fprintf(stderr, "pvrr: Embree error %d: %s\n", int(code), message ? message : "");
}

// An environment triangle in world space, double precision, precomputed once so that resolving a candidate
// costs no vertex gathering: vertex a, edges b - a and c - a, and the unit normal of (b - a) x (c - a).
// 96 bytes per triangle, for about 10 % more incoherent rays per second (tests/bench/rays.cpp).
struct EnvTriangle {
  Vec3 a, e1, e2, n;
};

// What an Embree geometry ID stands for.
struct GeomInfo {
  HitKind kind = HitKind::None;
  int index = -1;    // mesh or element
  int surface = 0;   // element surface
  std::vector<Vec2> params;  // element tessellation: (u, v) per vertex
  std::vector<Vec3> local;   // element tessellation: local positions (to move it with the element)
  std::vector<EnvTriangle> tris;  // environment: per triangle, in double
};


// Double-precision ray/triangle intersection (Moller-Trumbore) with edges e1 = b - a, e2 = c - a; returns t
// (or -1 for a ray parallel to the plane), and the barycentrics of b and c.
double intersectTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& e1, const Vec3& e2,
                         double& bu, double& bv) {
  Vec3 pv = glm::cross(d, e2);
  double det = glm::dot(e1, pv);
  if (det == 0.0) return -1;
  double inv = 1.0 / det;
  Vec3 tv = o - a;
  bu = glm::dot(tv, pv) * inv;
  Vec3 qv = glm::cross(tv, e1);
  bv = glm::dot(d, qv) * inv;
  return glm::dot(e2, qv) * inv;
}

}  // namespace

bool refineRaySurface(const cad::Surface& s, const Vec3& o, const Vec3& d, Vec2& uv, double& t, bool clamp) {
  const cad::ParamDomain dom = s.domain();
  const double scale = std::max({1.0, glm::length(o), std::abs(t)});
  // Convergence at a few ulps of the coordinates' magnitude: the best double precision can give.
  const double tol = 8.0 * std::numeric_limits<double>::epsilon() * scale;
  // A surface undefined at a Newton step (a steep sphere's extension past |R|, followed for a rim ray: the +8 D
  // lens of docs/robustness.md's hunt was refused there) is no intersection, not an error.
  cad::SurfaceDerivs sd;
  const auto evaluated = [&s, &sd](const Vec2& p) {
    try {
      sd = s.evaluate(p.x, p.y);
      return true;
    } catch (const Error&) {
      return false;
    }
  };
  for (int it = 0; it < 30; ++it) {
    if (!evaluated(uv)) return false;
    Vec3 f = sd.p - (o + t * d);
    if (glm::length(f) <= tol) return std::isfinite(t);
    // Solve [du dv -d] (du, dv, dt)^T = -f.
    Mat3 j(sd.du, sd.dv, -d);
    double det = glm::determinant(j);
    if (!std::isfinite(det) || det == 0.0) return false;
    Vec3 step = glm::inverse(j) * (-f);
    uv += Vec2(step.x, step.y);
    t += step.z;
    // A root outside the domain is no intersection; clamping lets a boundary hit still converge.
    if (clamp) {
      uv.x = std::clamp(uv.x, dom.u0, dom.u1);
      uv.y = std::clamp(uv.y, dom.v0, dom.v1);
    }
  }
  // Stalled within a few hundred ulps (a grazing hit): accept; anything worse is no intersection.
  if (!evaluated(uv)) return false;
  return std::isfinite(t) && glm::length(sd.p - (o + t * d)) < 64.0 * tol;
}

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;  // the static meshes and the elements
  // With animated meshes: `dynamic` holds them, and `top` instances `scene` and `dynamic` (the IDs of its two
  // instances after every geometry's); the queries traverse `top`. Without: top == scene, dynamic null.
  RTCScene top = nullptr, dynamic = nullptr;
  unsigned static_instance = RTC_INVALID_GEOMETRY_ID, dynamic_instance = RTC_INVALID_GEOMETRY_ID;
  std::vector<int> mesh_geom;      // per environment mesh: its geometry ID, or -1 (no triangles)
  std::vector<Mat4> mesh_motion;   // per environment mesh: the Scene::mesh_motion its triangles were placed with
  std::vector<Mat4> element_pose;  // per element: the local_to_world its tessellations were placed with
  Vec3 anchor{0};  // world position subtracted before converting to float
  std::vector<GeomInfo> geoms;
  // Element surface -> geometry ID in `scene`.
  std::vector<std::array<int, 2>> element_geoms;
  // Element surface -> a scene holding only that surface's tessellation (the same Embree geometry as in
  // `scene`, attached to both), for single-surface queries: one traversal of a small BVH instead of
  // stepping through every other hit along the ray in the whole scene.
  std::vector<std::array<RTCScene, 2>> element_scenes;
  // Per mirror element (null for lenses): its candidate vertices (element-local) in chunks of kClearanceChunk
  // with their bounding boxes, the box of them all; the last tangentClearance() query and answer; and the
  // scene with every geometry but the element's (the same Embree geometries under the same IDs), built by
  // the first tangentClearance() that finds a point clear (intersectBeside).
  struct Clearance {
    std::vector<std::array<Vec3, 2>> chunk_boxes;
    Vec3 lo{0}, hi{0};
    std::mutex mutex;  // guards points, normals and answer, and the installing and committing of `beside`
    std::vector<Vec3> points, normals;
    std::shared_ptr<const RayScene::TangentClearance> answer;
    std::atomic<RTCScene> beside{nullptr};  // the scene queried (with animated meshes: an instance of
                                            // beside_static and one of `dynamic`)
    RTCScene beside_static = nullptr;       // with animated meshes: everything static but the element
  };
  std::vector<std::unique_ptr<Clearance>> clearance;
  bool moving = false;  // RaySceneOptions::moving_elements took effect: dynamic scenes
  ~Impl() {
    for (const auto& c : clearance) {
      if (c && c->beside.load()) rtcReleaseScene(c->beside.load());
      if (c && c->beside_static) rtcReleaseScene(c->beside_static);
    }
    if (top && top != scene) rtcReleaseScene(top);
    if (dynamic) rtcReleaseScene(dynamic);
    for (auto& pair : element_scenes)
      for (RTCScene s : pair)
        if (s) rtcReleaseScene(s);
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// Attaches a triangle geometry to `scn` under ID `id` (the IDs are unique across the static and the dynamic
// scene: a hit's geomID names its GeomInfo in either).
void addTriangles(RTCDevice dev, RTCScene scn, unsigned id, const std::vector<glm::vec3>& verts,
                  const std::vector<glm::u32vec3>& tris) {
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), verts.size()));
  for (size_t i = 0; i < verts.size(); ++i) {
    v[3 * i] = verts[i].x;
    v[3 * i + 1] = verts[i].y;
    v[3 * i + 2] = verts[i].z;
  }
  auto* idx = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
  for (size_t i = 0; i < tris.size(); ++i) {
    idx[3 * i] = tris[i].x;
    idx[3 * i + 1] = tris[i].y;
    idx[3 * i + 2] = tris[i].z;
  }
  rtcCommitGeometry(g);
  rtcAttachGeometryByID(scn, g, id);
  rtcReleaseGeometry(g);
}

// An instance of `child` with the identity transform, attached to `parent` under ID `id`: Embree transforms
// the ray by the identity (multiplications by 1 and additions of 0), so the child sees the very float ray.
void addInstance(RTCDevice dev, RTCScene parent, RTCScene child, unsigned id) {
  RTCGeometry inst = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(inst, child);
  const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
  rtcCommitGeometry(inst);
  rtcAttachGeometryByID(parent, inst, id);
  rtcReleaseGeometry(inst);
}

// A scene over `inner` (static) and `dynamic`, for the queries: instances under IDs after every geometry's.
RTCScene twoLevel(RTCDevice dev, RTCScene inner, RTCScene dynamic, unsigned first_id) {
  RTCScene t = rtcNewScene(dev);
  addInstance(dev, t, inner, first_id);
  addInstance(dev, t, dynamic, first_id + 1);
  rtcCommitScene(t);
  return t;
}

// Recommits `top`'s instances (their child scenes were committed) and `top`.
void recommitTop(RTCScene top, unsigned first_id) {
  for (unsigned id : {first_id, first_id + 1}) rtcCommitGeometry(rtcGetGeometry(top, id));
  rtcCommitScene(top);
}

// An environment mesh's vertices relative to the scene's anchor, in float.
std::vector<glm::vec3> meshVertices(const EnvMesh& mesh, const Vec3& anchor) {
  std::vector<glm::vec3> verts(mesh.positions.size());
  const Vec3 shift = mesh.anchor - anchor;
  for (size_t i = 0; i < verts.size(); ++i) verts[i] = glm::vec3(Vec3(mesh.positions[i]) + shift);
  return verts;
}

// An environment mesh's triangles in double (EnvTriangle).
std::vector<EnvTriangle> meshTriangles(const EnvMesh& mesh) {
  std::vector<EnvTriangle> tris(mesh.triangles.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    const glm::u32vec3 tri = mesh.triangles[t];
    const Vec3 a = mesh.anchor + Vec3(mesh.positions[tri.x]);
    const Vec3 b = mesh.anchor + Vec3(mesh.positions[tri.y]);
    const Vec3 c = mesh.anchor + Vec3(mesh.positions[tri.z]);
    tris[t] = EnvTriangle{a, b - a, c - a, glm::normalize(glm::cross(b - a, c - a))};
  }
  return tris;
}

}  // namespace

RayScene::RayScene(const Scene& scene, RaySceneOptions options) : scene_(scene), impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  const char* config = std::getenv("PVRR_EMBREE_CONFIG");
  im.device = rtcNewDevice(config);
  if (!im.device)
    throw Error("Embree: could not create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")" +
                (config ? std::string(" with PVRR_EMBREE_CONFIG=\"") + config + "\"" : std::string()));
  rtcSetDeviceErrorFunction(im.device, embreeError, nullptr);
  im.scene = rtcNewScene(im.device);
  rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_HIGH);
  // RaySceneOptions::moving_elements: a dynamic scene, which Embree builds in two levels, so that a pose
  // update refits the moved elements' BVHs and rebuilds the top level, not the environment's.
  const bool moving = options.moving_elements &&
                            std::any_of(scene.elements.begin(), scene.elements.end(),
                                        [](const Element& e) { return e.attached_to_observer; });
  if (moving) {
    rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_LOW);
  }
  im.anchor = scene.observer.eye;
  epsilon_ = 1e-9 * std::max(1.0, scene.boundsRadius()) + 1e-12 * glm::length(im.anchor);

  // The animated meshes' own scene: rebuilt whole when they move (it is small), its BVH of low quality.
  bool any_dynamic = false;
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    any_dynamic = any_dynamic || (scene.meshAnimated(m) && !scene.meshes[m].triangles.empty());
  if (any_dynamic) {
    im.dynamic = rtcNewScene(im.device);
    rtcSetSceneFlags(im.dynamic, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(im.dynamic, RTC_BUILD_QUALITY_LOW);
  }
  unsigned next_id = 0;
  im.mesh_geom.assign(scene.meshes.size(), -1);
  im.mesh_motion.assign(scene.meshes.size(), Mat4(1.0));
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvMesh& mesh = scene.meshes[m];
    if (mesh.triangles.empty()) continue;
    const unsigned id = next_id++;
    addTriangles(im.device, scene.meshAnimated(m) ? im.dynamic : im.scene, id, meshVertices(mesh, im.anchor),
                 mesh.triangles);
    if (im.geoms.size() <= id) im.geoms.resize(id + 1);
    im.geoms[id] = GeomInfo{HitKind::Environment, int(m), 0, {}, {}, meshTriangles(mesh)};
    im.mesh_geom[m] = int(id);
    im.mesh_motion[m] = scene.meshMotion(m);
  }
  im.element_geoms.assign(scene.elements.size(), {-1, -1});
  for (const Element& el : scene.elements) im.element_pose.push_back(el.local_to_world);
  im.element_scenes.assign(scene.elements.size(), {nullptr, nullptr});
  for (size_t e = 0; e < scene.elements.size(); ++e) {
    const Element& el = scene.elements[e];
    const int nsurf = el.type == ElementType::Lens ? 2 : 1;
    for (int s = 0; s < nsurf; ++s) {
      const cad::Surface& surf = s == 0 ? el.frontSurface() : *el.lens.back;
      const cad::Outline* outline = el.has_outline ? &el.outline : nullptr;
      cad::Tessellation tess = cad::tessellateGrid(surf, options.element_tessellation,
                                                   options.element_tessellation, outline);
      std::vector<glm::vec3> verts(tess.positions.size());
      for (size_t i = 0; i < verts.size(); ++i) verts[i] = glm::vec3(el.toWorldPoint(tess.positions[i]) - im.anchor);
      const unsigned id = next_id++;
      addTriangles(im.device, im.scene, id, verts, tess.triangles);
      if (moving) {
        // Moved rigidly by updateElementPoses: the topology stays, so the BVH is refitted, not rebuilt.
        RTCGeometry g = rtcGetGeometry(im.scene, id);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT);
        rtcCommitGeometry(g);
      }
      if (im.geoms.size() <= id) im.geoms.resize(id + 1);
      im.geoms[id] = GeomInfo{HitKind::Element, int(e), s, std::move(tess.params), std::move(tess.positions), {}};
      im.element_geoms[e][size_t(s)] = int(id);
      RTCScene own = rtcNewScene(im.device);
      im.element_scenes[e][size_t(s)] = own;
      rtcSetSceneBuildQuality(own, moving ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_HIGH);
      if (moving) rtcSetSceneFlags(own, RTC_SCENE_FLAG_DYNAMIC);
      rtcAttachGeometryByID(own, rtcGetGeometry(im.scene, id), 0);
      rtcCommitScene(own);
    }
  }
  rtcCommitScene(im.scene);
  im.top = im.scene;
  if (im.dynamic) {
    rtcCommitScene(im.dynamic);
    im.static_instance = next_id;
    im.top = twoLevel(im.device, im.scene, im.dynamic, im.static_instance);
  }
  im.moving = moving;
  im.clearance.resize(scene.elements.size());
  for (size_t e = 0; e < scene.elements.size(); ++e) {
    if (scene.elements[e].type != ElementType::Mirror) continue;
    const std::vector<Vec3>& local = im.geoms[size_t(im.element_geoms[e][0])].local;
    if (local.empty()) continue;
    auto c = std::make_unique<Impl::Clearance>();
    c->lo = c->hi = local[0];
    for (size_t from = 0; from < local.size(); from += kClearanceChunk) {
      std::array<Vec3, 2> box{local[from], local[from]};
      for (size_t j = from; j < std::min(local.size(), from + kClearanceChunk); ++j) {
        box[0] = glm::min(box[0], local[j]);
        box[1] = glm::max(box[1], local[j]);
      }
      c->chunk_boxes.push_back(box);
      c->lo = glm::min(c->lo, box[0]);
      c->hi = glm::max(c->hi, box[1]);
    }
    im.clearance[e] = std::move(c);
  }
  RTCError err = rtcGetDeviceError(im.device);
  if (err != RTC_ERROR_NONE) throw Error("Embree: scene build failed (error " + std::to_string(int(err)) + ")");
}

RayScene::~RayScene() = default;

void RayScene::updateElementPoses() {
  Impl& im = *impl_;
  // Only the elements that moved since their tessellations were placed: a commit without them costs nothing.
  std::vector<bool> moved(scene_.elements.size());
  bool any = false;
  for (size_t e = 0; e < moved.size(); ++e) {
    moved[e] = scene_.elements[e].local_to_world != im.element_pose[e];
    any = any || moved[e];
    im.element_pose[e] = scene_.elements[e].local_to_world;
  }
  if (!any) return;
  for (size_t id = 0; id < im.geoms.size(); ++id) {
    const GeomInfo& g = im.geoms[id];
    if (g.kind != HitKind::Element || !moved[size_t(g.index)]) continue;
    const Element& el = scene_.elements[size_t(g.index)];
    RTCGeometry geom = rtcGetGeometry(im.scene, unsigned(id));
    auto* v = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    for (size_t i = 0; i < g.local.size(); ++i) {
      const Vec3 p = el.toWorldPoint(g.local[i]) - im.anchor;
      v[3 * i] = float(p.x);
      v[3 * i + 1] = float(p.y);
      v[3 * i + 2] = float(p.z);
    }
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
  }
  rtcCommitScene(im.scene);
  if (im.dynamic) recommitTop(im.top, im.static_instance);
  for (const auto& c : im.clearance) {
    if (!c) continue;
    std::lock_guard<std::mutex> lock(c->mutex);
    if (c->beside_static) {
      rtcCommitScene(c->beside_static);
      recommitTop(c->beside.load(), im.static_instance);
    } else if (c->beside.load()) {
      rtcCommitScene(c->beside.load());
    }
  }
  for (auto& pair : im.element_scenes)
    for (RTCScene s : pair)
      if (s) rtcCommitScene(s);
}

bool RayScene::hasDynamicMeshes() const { return impl_->dynamic != nullptr; }

int RayScene::updateEnvironmentMeshes() {
  Impl& im = *impl_;
  int moved = 0;
  for (size_t m = 0; m < im.mesh_geom.size() && im.dynamic; ++m) {
    if (im.mesh_geom[m] < 0 || !scene_.meshAnimated(m) || scene_.meshMotion(m) == im.mesh_motion[m]) continue;
    const EnvMesh& mesh = scene_.meshes[m];
    const unsigned id = unsigned(im.mesh_geom[m]);
    RTCGeometry geom = rtcGetGeometry(im.dynamic, id);
    auto* v = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    const std::vector<glm::vec3> verts = meshVertices(mesh, im.anchor);
    for (size_t i = 0; i < verts.size(); ++i) {
      v[3 * i] = verts[i].x;
      v[3 * i + 1] = verts[i].y;
      v[3 * i + 2] = verts[i].z;
    }
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
    im.geoms[id].tris = meshTriangles(mesh);
    im.mesh_motion[m] = scene_.meshMotion(m);
    ++moved;
  }
  if (moved == 0) return 0;
  rtcCommitScene(im.dynamic);
  recommitTop(im.top, im.static_instance);
  for (const auto& c : im.clearance) {
    if (!c) continue;
    std::lock_guard<std::mutex> lock(c->mutex);
    if (c->beside_static) recommitTop(c->beside.load(), im.static_instance);
  }
  const RTCError err = rtcGetDeviceError(im.device);
  if (err != RTC_ERROR_NONE)
    throw Error("Embree: updating the animated meshes failed (error " + std::to_string(int(err)) + ")");
  return moved;
}

namespace {

// The float ray of one query: origin relative to the anchor, the interval widened by the float slack.
struct FloatRay {
  float org[3], dir[3], tnear, tfar;
};

// The float origin can be off by half an ulp of |o - anchor|; the interval is widened by that much and the
// double-precision test decides.
double floatSlack(const Vec3& ol) { return 4.0 * std::numeric_limits<float>::epsilon() * (glm::length(ol) + 1e-3); }

FloatRay floatRay(const Vec3& o, const Vec3& d, const Vec3& anchor, double tnear, double t_max, float past) {
  const Vec3 ol = o - anchor;
  const double slack = floatSlack(ol);
  FloatRay r;
  r.org[0] = float(ol.x);
  r.org[1] = float(ol.y);
  r.org[2] = float(ol.z);
  r.dir[0] = float(d.x);
  r.dir[1] = float(d.y);
  r.dir[2] = float(d.z);
  r.tnear = std::max(float(std::max(0.0, tnear - slack)), past);
  r.tfar = std::isfinite(t_max) ? float(t_max + slack) : std::numeric_limits<float>::infinity();
  return r;
}

// A single Embree query for floatRay(...), no hit yet.
RTCRayHit rayHit1(const FloatRay& fr) {
  RTCRayHit rh{};
  rh.ray.org_x = fr.org[0];
  rh.ray.org_y = fr.org[1];
  rh.ray.org_z = fr.org[2];
  rh.ray.dir_x = fr.dir[0];
  rh.ray.dir_y = fr.dir[1];
  rh.ray.dir_z = fr.dir[2];
  rh.ray.tnear = fr.tnear;
  rh.ray.tfar = fr.tfar;
  rh.ray.mask = ~0u;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// The surface parameters of an element candidate: the tessellation's (u, v) at its vertices interpolated
// with Embree's barycentrics (bu, bv of the triangle's vertices 1 and 2).
Vec2 candidateParams(RTCScene scene, const GeomInfo& g, unsigned geom_id, unsigned prim_id, double bu, double bv) {
  const RTCGeometry geom = rtcGetGeometry(scene, geom_id);
  const auto* idx = static_cast<const unsigned*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
  const unsigned* tri = idx + 3 * size_t(prim_id);
  return (1.0 - bu - bv) * g.params[tri[0]] + bu * g.params[tri[1]] + bv * g.params[tri[2]];
}

}  // namespace

bool RayScene::resolveCandidate(const Vec3& o, const Vec3& d, double t_min, double t_max, unsigned geom_id,
                                unsigned prim_id, float bu_f, float bv_f, float t_candidate, RayHit& hit) const {
  const Impl& im = *impl_;
  const GeomInfo& g = im.geoms[geom_id];
  if (g.kind == HitKind::Environment) {
    const EnvTriangle& et = g.tris[prim_id];
    double bu = 0, bv = 0;
    const double t = intersectTriangle(o, d, et.a, et.e1, et.e2, bu, bv);
    // Float and double disagree at the interval's edge: the caller steps past this triangle.
    if (!(t > t_min) || t >= t_max) return false;
    hit = RayHit{};
    hit.kind = HitKind::Environment;
    hit.t = t;
    hit.point = o + t * d;
    hit.normal = et.n;
    const EnvMesh& mesh = scene_.meshes[size_t(g.index)];
    const glm::u32vec3 tri = mesh.triangles[prim_id];
    const double bw = 1.0 - bu - bv;
    hit.uv = bw * Vec2(mesh.uvs[tri.x]) + bu * Vec2(mesh.uvs[tri.y]) + bv * Vec2(mesh.uvs[tri.z]);
    hit.mesh = g.index;
    hit.triangle = int(prim_id);
    return true;
  }
  // Element candidate: refined on the exact surface.
  const Vec2 uv = candidateParams(im.scene, g, geom_id, prim_id, bu_f, bv_f);
  hit = refineElementHit(g.index, g.surface, o, d, t_min, t_max, uv, double(t_candidate), true);
  return hit.hit();
}

RayHit RayScene::intersect(const Vec3& o, const Vec3& d, double t_min, double t_max) const {
  return intersectIn(-1, o, d, t_min, t_max);
}

RayHit RayScene::intersectBeside(int element, const Vec3& o, const Vec3& d, double t_min, double t_max) const {
  PVRR_CHECK(element >= 0 && size_t(element) < impl_->clearance.size() && impl_->clearance[size_t(element)] &&
                 impl_->clearance[size_t(element)]->beside.load(std::memory_order_acquire),
             << "element " << element << ": no tangentClearance() found a point of it clear");
  return intersectIn(element, o, d, t_min, t_max);
}

RayHit RayScene::intersectIn(int beside_element, const Vec3& o, const Vec3& d, double t_min, double t_max) const {
  // A ray that is not finite (degenerate input upstream) meets nothing; Embree asserts on it.
  if (!std::isfinite(o.x + o.y + o.z + d.x + d.y + d.z)) return RayHit{};
  const Impl& im = *impl_;
  RTCScene scene =
      beside_element < 0 ? im.top : im.clearance[size_t(beside_element)]->beside.load(std::memory_order_acquire);
  // After a rejected candidate the next query starts strictly beyond it (the float slack must not bring the
  // same triangle back).
  float past = 0.0f;
  // A candidate on an element's tessellation whose exact hit falls outside the element is skipped and the
  // ray continues; a handful of retries covers every case seen in practice.
  for (int attempt = 0; attempt < 8; ++attempt) {
    // Default context flags: incoherent (secondary rays).
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = rayHit1(floatRay(o, d, im.anchor, t_min, t_max, past));
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return RayHit{};
    RayHit hit;
    if (resolveCandidate(o, d, t_min, t_max, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar, hit))
      return hit;
    past = std::nextafter(rh.ray.tfar, std::numeric_limits<float>::infinity());
  }
  return RayHit{};
}

void RayScene::intersectPacket(const Vec3* o, const Vec3* d, int count, RayHit* out, double t_min,
                               double t_max, bool coherent) const {
  PVRR_CHECK(count >= 0 && count <= kPacketSize, << count);
  const Impl& im = *impl_;
  alignas(64) RTCRayHit16 rh;
  alignas(64) int valid[kPacketSize];
  for (int i = 0; i < kPacketSize; ++i) {
    valid[i] = i < count ? -1 : 0;
    // Inactive lanes still get a well-formed (empty) ray.
    const FloatRay fr = i < count ? floatRay(o[i], d[i], im.anchor, t_min, t_max, 0.0f)
                                  : FloatRay{{0, 0, 0}, {0, 0, 1}, 0.0f, -1.0f};
    rh.ray.org_x[i] = fr.org[0];
    rh.ray.org_y[i] = fr.org[1];
    rh.ray.org_z[i] = fr.org[2];
    rh.ray.dir_x[i] = fr.dir[0];
    rh.ray.dir_y[i] = fr.dir[1];
    rh.ray.dir_z[i] = fr.dir[2];
    rh.ray.tnear[i] = fr.tnear;
    rh.ray.tfar[i] = fr.tfar;
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = ~0u;
    rh.ray.id[i] = unsigned(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  // Coherent rays: Embree's packet traversal is several times faster with this flag (and several times
  // slower with it on incoherent rays; see shared/notes/platform.md).
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  rtcIntersect16(valid, im.top, &ctx, &rh);
  for (int i = 0; i < count; ++i) {
    if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
      out[i] = RayHit{};
      continue;
    }
    // The first candidate is resolved here exactly as intersect() resolves it; a rejected one sends the
    // lane through the single-ray loop (which repeats this first step and goes on past the candidate).
    if (!resolveCandidate(o[i], d[i], t_min, t_max, rh.hit.geomID[i], rh.hit.primID[i], rh.hit.u[i], rh.hit.v[i],
                          rh.ray.tfar[i], out[i]))
      out[i] = intersect(o[i], d[i], t_min, t_max);
  }
}

std::shared_ptr<const RayScene::TangentClearance> RayScene::tangentClearance(int element,
                                                                             const std::vector<Vec3>& points,
                                                                             const std::vector<Vec3>& normals) const {
  Impl& im = *impl_;
  PVRR_CHECK(element >= 0 && size_t(element) < scene_.elements.size(), << element);
  PVRR_CHECK(points.size() == normals.size(), << points.size() << " points, " << normals.size() << " normals");
  auto out = std::make_shared<TangentClearance>();
  if (!im.clearance[size_t(element)]) return out;  // a lens, or no candidates
  Impl::Clearance& c = *im.clearance[size_t(element)];
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    if (c.answer && c.points == points && c.normals == normals) return c.answer;
  }
  // Computed without the lock (its parallel loop may run other tasks on this thread).
  const std::vector<Vec3>& local = im.geoms[size_t(im.element_geoms[size_t(element)][0])].local;
  const double size = std::max(glm::length(c.hi - c.lo), 1e-9);
  const double cap = kClearanceCap * size;
  out->tolerance = kClearanceTolerance * size;
  const size_t chunks = c.chunk_boxes.size();
  out->ahead.resize(points.size());
  out->behind.resize(points.size());
  // Branch and bound per point: each chunk's box bounds its vertices' distances; the chunk with the largest
  // bound is searched first, then every other chunk whose bound exceeds the extreme so far, until the extreme
  // passes the cap.
  tbb::parallel_for(size_t(0), points.size(), [&](size_t i) {
    const Vec3 p = points[i], n = glm::normalize(normals[i]);
    const double pn = glm::dot(p, n);
    if (!std::isfinite(pn)) {  // a point or normal not finite (a degenerate normal): never clear
      out->ahead[i] = kInf;
      out->behind[i] = -kInf;
      return;
    }
    std::vector<double> bound(chunks);
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0;  // ahead: the largest of (x - p) . n; behind: of -(x - p) . n
      const Vec3 m = sign * n;
      size_t first = 0;
      for (size_t k = 0; k < chunks; ++k) {
        const auto& b = c.chunk_boxes[k];
        bound[k] = std::max(b[0].x * m.x, b[1].x * m.x) + std::max(b[0].y * m.y, b[1].y * m.y) +
                   std::max(b[0].z * m.z, b[1].z * m.z) - sign * pn;
        if (bound[k] > bound[first]) first = k;
      }
      double best = -kInf;
      const auto search = [&](size_t k) {
        for (size_t j = k * kClearanceChunk; j < std::min(local.size(), (k + 1) * kClearanceChunk); ++j)
          best = std::max(best, glm::dot(local[j] - p, m));
      };
      search(first);
      for (size_t k = 0; k < chunks && best <= cap; ++k)
        if (k != first && bound[k] > best) search(k);
      const double value = best <= cap ? best : kInf;  // beyond the cap: never clear
      (side == 0 ? out->ahead[i] : out->behind[i]) = sign * value;
    }
  });
  bool any_clear = false;
  for (size_t i = 0; i < points.size() && !any_clear; ++i)
    any_clear = out->ahead[i] <= out->tolerance || out->behind[i] >= -out->tolerance;
  // The scene beside the element, once: built outside the lock (Embree's build runs tasks), installed under it.
  RTCScene built = nullptr, built_static = nullptr;
  if (any_clear && !c.beside.load(std::memory_order_acquire)) {
    built = rtcNewScene(im.device);
    if (!built) throw Error("Embree: could not create the scene beside element " + std::to_string(element));
    rtcSetSceneBuildQuality(built, im.moving ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_HIGH);
    if (im.moving) rtcSetSceneFlags(built, RTC_SCENE_FLAG_DYNAMIC);
    for (size_t id = 0; id < im.geoms.size(); ++id) {
      const GeomInfo& g = im.geoms[id];
      const bool in_dynamic = g.kind == HitKind::Environment && scene_.meshAnimated(size_t(g.index));
      if (g.kind != HitKind::None && !in_dynamic && !(g.kind == HitKind::Element && g.index == element))
        rtcAttachGeometryByID(built, rtcGetGeometry(im.scene, unsigned(id)), unsigned(id));
    }
    rtcCommitScene(built);
    if (im.dynamic) {  // the queried scene instances it and the animated meshes' scene
      built_static = built;
      built = twoLevel(im.device, built_static, im.dynamic, im.static_instance);
    }
    const RTCError err = rtcGetDeviceError(im.device);
    if (err != RTC_ERROR_NONE) {
      rtcReleaseScene(built);
      if (built_static) rtcReleaseScene(built_static);
      throw Error("Embree: building the scene beside element " + std::to_string(element) + " failed (error " +
                  std::to_string(int(err)) + ")");
    }
  }
  std::lock_guard<std::mutex> lock(c.mutex);
  if (built) {
    if (c.beside.load()) {  // another thread was first
      rtcReleaseScene(built);
      if (built_static) rtcReleaseScene(built_static);
    } else {
      c.beside_static = built_static;
      c.beside.store(built, std::memory_order_release);
    }
  }
  c.points = points;
  c.normals = normals;
  c.answer = out;
  return out;
}

RayHit RayScene::intersectElementSurface(int element, int surface, const Vec3& o, const Vec3& d, double t_min,
                                         double t_max, bool within_outline) const {
  if (!std::isfinite(o.x + o.y + o.z + d.x + d.y + d.z)) return RayHit{};
  const Impl& im = *impl_;
  const int gid = im.element_geoms[size_t(element)][size_t(surface)];
  if (gid < 0) return RayHit{};
  const GeomInfo& g = im.geoms[size_t(gid)];
  // Candidate: the nearest hit on this surface's own tessellation.
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  double from = t_min;
  for (int attempt = 0; attempt < 4; ++attempt) {
    RTCRayHit rh = rayHit1(floatRay(o, d, im.anchor, from, t_max, 0.0f));
    rtcIntersect1(im.element_scenes[size_t(element)][size_t(surface)], &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)  // no candidate: the direct solve, unless one was refuted
      return attempt == 0 ? refineElementHit(element, surface, o, d, t_min, t_max, Vec2(0), -1, within_outline) : RayHit{};
    const double t = rh.ray.tfar;
    const Vec2 uv = candidateParams(im.scene, g, unsigned(gid), rh.hit.primID, rh.hit.u, rh.hit.v);
    const RayHit hit = refineElementHit(element, surface, o, d, t_min, t_max, uv, t, within_outline);
    if (hit.hit()) return hit;
    // The candidate refined to nothing beyond t_min: typically the ray's own start on this surface (a ray
    // totally reflected inside a lens, whose float start lies a hair behind the tessellation). Look on
    // along the ray for the next candidate.
    from = t + 2 * floatSlack(o - im.anchor) + 1e-9 * std::abs(t);  // floatRay widens back by one slack
  }
  return RayHit{};
}

RayHit RayScene::refineElementHit(int element, int surface, const Vec3& o, const Vec3& d, double t_min,
                                  double t_max, Vec2 uv, double t, bool within_outline) const {
  const Element& el = scene_.elements[size_t(element)];
  const cad::Surface& surf = surface == 0 ? el.frontSurface() : *el.lens.back;
  const Vec3 ol_local = el.toLocalPoint(o);
  const Vec3 dl = el.toLocalDir(d);
  if (t < 0) {
    // No candidate: the tessellation is a polygon inscribed in the outline, so hits within a chord of the
    // rim can miss it. A sag surface can be solved directly: start where the ray crosses its vertex plane.
    const auto* sag = dynamic_cast<const cad::SagSurface*>(&surf);
    if (!sag || std::abs(dl.z) < 1e-12) return RayHit{};
    t = (sag->zVertex() - ol_local.z) / dl.z;
    if (!(t > t_min) || t >= t_max) return RayHit{};
    uv = Vec2(ol_local.x + t * dl.x, ol_local.y + t * dl.y);
    if (within_outline && !el.outline.contains(uv, 0.01 * std::max(el.outline.width(), el.outline.height())))
      return RayHit{};
  }
  const bool extend = !within_outline && dynamic_cast<const cad::SagSurface*>(&surf) != nullptr;
  if (!refineRaySurface(surf, ol_local, dl, uv, t, !extend)) return RayHit{};
  if (!(t > t_min) || t >= t_max) return RayHit{};
  if (within_outline && el.has_outline && !el.outline.contains(uv, 1e-12)) return RayHit{};
  RayHit hit;
  hit.kind = HitKind::Element;
  hit.t = t;
  hit.point = o + t * d;
  hit.normal = glm::normalize(el.toWorldDir(surf.normal(uv.x, uv.y)));
  hit.element = element;
  hit.surface = surface;
  hit.param = uv;
  return hit;
}

}  // namespace pvrr

// Ray queries against a Scene with Embree, exact to double precision:
// - environment triangles are found by Embree (float, relative to one scene anchor near the observer) and
//   the hit is recomputed in double on the hit triangle;
// - optical elements are found on a fine tessellation and the hit is then refined by Newton iterations on
//   the element's exact surface, so results do not depend on that tessellation;
// - animated environment meshes (Scene::meshAnimated) live in a small scene of their own beside the static
//   one, both instanced (with the identity: the float rays are unchanged) in the scene the queries traverse,
//   so that moving them (updateEnvironmentMeshes) rebuilds only their own small BVH (issue 24's
//   static/dynamic split). A scene without animated meshes is one Embree scene, as before.
// No Embree type appears here.
#pragma once
#include <memory>
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr {

enum class HitKind { None, Environment, Element };

struct RayHit {
  HitKind kind = HitKind::None;
  double t = kInf;
  Vec3 point{0};
  Vec3 normal{0};       // unit geometric normal (environment: the triangle's; element: the exact surface's,
                        // oriented as the surface: +z side of the element's local frame)
  Vec2 uv{0};           // environment texture coordinates
  int mesh = -1;        // environment mesh index
  int triangle = -1;    // environment: the hit triangle, an index into that mesh's triangles
  int element = -1;     // element index
  int surface = 0;      // element surface: 0 = front (mirror surface, lens eye side), 1 = lens back
  Vec2 param{0};        // element surface parameters (u, v) of the exact hit
  bool hit() const { return kind != HitKind::None; }
};

struct RaySceneOptions {
  int element_tessellation = 96;  // grid used only to find candidate element hits
  // Elements attached to the observer will move every frame (updateElementPoses during a head turn): build
  // a two-level dynamic scene whose pose update refits the moved elements (far cheaper than a full rebuild),
  // at the price of slower queries (low-quality top level); figures: docs/method.md "Measurements behind the
  // design".
  bool moving_elements = false;
};

class RayScene {
 public:
  // The Embree device takes its configuration string from the environment variable PVRR_EMBREE_CONFIG when
  // set (e.g. "max_isa=avx2" or "verbose=1"; Embree's rtcNewDevice syntax), for benchmarking kernels.
  explicit RayScene(const Scene& scene, RaySceneOptions options = {});
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // Nearest hit on o + t d (d unit) for t in (t_min, t_max).
  RayHit intersect(const Vec3& o, const Vec3& d, double t_min = 0, double t_max = kInf) const;

  // The most rays one intersectPacket() call takes.
  static constexpr int kPacketSize = 16;
  // intersect() for `count` (<= kPacketSize) rays as one Embree packet: out[i] is
  // intersect(o[i], d[i], t_min, t_max), to the last bit when Embree's packet and single-ray kernels agree
  // on the candidate triangle. Lanes whose candidate needs more than the first query (a candidate rejected
  // by the exact test) are finished with the single-ray code. `coherent`: the rays are coherent (e.g. the
  // primary rays of a 4 x 4 pixel tile), which makes Embree's packet traversal several times faster; on
  // incoherent rays the flag makes it several times slower, so pass false for those.
  void intersectPacket(const Vec3* o, const Vec3* d, int count, RayHit* out, double t_min = 0,
                       double t_max = kInf, bool coherent = true) const;
  // Exact intersection with one surface of one element only (e.g. a lens's back surface from inside).
  // `within_outline` false: a sag surface is intersected as its analytic extension beyond the outline
  // (used to continue a lens's rim rays smoothly; see vertex_stage.cpp).
  RayHit intersectElementSurface(int element, int surface, const Vec3& o, const Vec3& d, double t_min = 0,
                                 double t_max = kInf, bool within_outline = true) const;

  // Where a mirror element's candidate tessellation lies against the tangent planes of points on its surface
  // (element-local positions and normals, e.g. the vertex stage's grid): per point p with unit normal n, the
  // largest (`ahead`) and the smallest (`behind`) signed distance (x - p) . n over the candidate vertices x,
  // exact where within kClearanceCap of the mirror's size, else +inf (ahead) or -inf (behind). A convex
  // mirror's candidates lie wholly behind each tangent plane: ahead <= 0 to double rounding (`tolerance`,
  // kClearanceTolerance of the size); a plane's lie on it. The answer to the last set of points is kept per
  // element: asking again with the same points costs one comparison. Empty for a lens.
  struct TangentClearance {
    std::vector<double> ahead, behind;
    double tolerance = 0;
  };
  static constexpr double kClearanceCap = 1e-3, kClearanceTolerance = 1e-12;
  std::shared_ptr<const TangentClearance> tangentClearance(int element, const std::vector<Vec3>& points,
                                                           const std::vector<Vec3>& normals) const;
  // intersect() on everything but mirror element `element`, for a ray from a point p of it that cannot meet
  // its candidates: the ray leaves into the front, d . n >= kMinLeave, where tangentClearance's `ahead` at p
  // is at most its tolerance (or into the back, d . n <= -kMinLeave, where `behind` is at least minus it).
  // Float rounding moves candidates and the ray's origin by at most r (~2^-22 of their distance from the
  // scene's anchor), so the ray's height over the tangent plane, t (d . n), exceeds every candidate's beyond
  // t = 2 r / |d . n|: what the whole scene's query could report nearer lies within that distance of p (under
  // 0.1 mm for the car mirror), where the exact test finds p itself (t <= t_min) and rejects it. So the hit is
  // intersect()'s, without traversing the element's candidates, among which every such ray starts. Its scene
  // (a second BVH over everything else) is built by the first tangentClearance() that finds a point clear.
  static constexpr double kMinLeave = 1e-2;
  RayHit intersectBeside(int element, const Vec3& o, const Vec3& d, double t_min = 0, double t_max = kInf) const;

  // After elements moved (Element::local_to_world changed, e.g. spectacles turning with the head): moves
  // the candidate tessellations of those that moved in Embree and recommits (the scenes beside mirrors too);
  // nothing when none moved. The environment is untouched. As Embree requires, no query (intersect*, tangentClearance)
  // may run meanwhile.
  void updateElementPoses();
  // After animated environment meshes moved (Scene::mesh_motion changed, pvrr/scene/scene_build.h
  // applyAnimation): moves those meshes' triangles in Embree and recommits only the small scene that holds
  // the animated meshes (and the instances above it); the static meshes' BVH stays. Returns how many meshes
  // moved. The same rule as updateElementPoses: no query meanwhile.
  int updateEnvironmentMeshes();
  // Whether the scene holds animated environment meshes, in a scene of their own (Scene::meshAnimated).
  bool hasDynamicMeshes() const;

  const Scene& scene() const { return scene_; }
  // Offset that moves a secondary ray's origin off a surface, relative to the scene scale.
  double epsilon() const { return epsilon_; }

 private:
  struct Impl;
  // intersect() on the whole scene (beside_element < 0) or on everything but one mirror element.
  RayHit intersectIn(int beside_element, const Vec3& o, const Vec3& d, double t_min, double t_max) const;
  // The exact hit behind Embree's candidate (geometry, primitive, barycentrics, float distance) on o + t d
  // with t in (t_min, t_max); false when the exact test rejects the candidate.
  bool resolveCandidate(const Vec3& o, const Vec3& d, double t_min, double t_max, unsigned geom_id,
                        unsigned prim_id, float bu, float bv, float t_candidate, RayHit& hit) const;
  // The exact hit on one element surface from a candidate (uv, t) on its tessellation, or (t < 0) with no
  // candidate, by the direct solve of a sag surface.
  RayHit refineElementHit(int element, int surface, const Vec3& o, const Vec3& d, double t_min, double t_max,
                          Vec2 uv, double t, bool within_outline) const;
  const Scene& scene_;
  double epsilon_ = 1e-9;
  std::unique_ptr<Impl> impl_;
};

// Newton refinement of a ray/surface intersection from a starting guess (u, v, t). Returns false when it
// does not converge to a point inside the domain. Exposed for tests.
// With `clamp` false the iterate may leave the parameter domain (analytic sag surfaces only).
bool refineRaySurface(const cad::Surface& s, const Vec3& o, const Vec3& d, Vec2& uv, double& t, bool clamp = true);

}  // namespace pvrr

// The view volume of the 1st-pass reflection map (paper 3.3, 4.2, 4.3) and the texture coordinates of the
// per-vertex hit points in it (paper 3.4).
//
// Conventions: world space, metres, radians; OpenGL camera and clip conventions (camera looks down -z_eye,
// x right, y up; NDC in [-1, 1]^3 with glDepthRange(0, 1)); matrices glm::dmat4, column-major (m[col][row]).
// Texture coordinates (s, t) = (NDC.xy + 1) / 2: (0, 0) is the bottom-left corner of the map, as GL samples a
// texture rendered into an FBO and read back with glReadPixels (row 0 = bottom row).
//
// Forward volume (buildViewVolume). For each ray i of the patch: origin o_i on the mirror, hit point h_i.
// Depths are measured along `forward` from the eye: z(p) = (p - e) . forward.
//  - forward = the normalised mean of the ray directions (paper 3.3).
//  - Zooming region: hits with z(h_i) <= 0 lie behind the eye (a concave mirror or convex lens whose fitted
//    viewpoint lies between the surface and the scene: objects inside the focal length, paper Fig. 8b/d).
//    No frustum looking along `forward` can contain them; they are listed in `zooming`, left out of this
//    volume, and `reversed` is set: render them with buildReversedViewVolume.
//  - near: beyond every mirror vertex (so the mirror itself, and everything behind it, is clipped) and before
//    every hit point: near = max_i z(o_i) + min(near_gap_m, half the gap to the nearest hit), and at least
//    min_near_fraction of the nearest hit's depth (a concave mirror's vertices all lie behind its eye, where
//    they are clipped anyway; the floor keeps the depth buffer usable). If some hit is nearer than the
//    farthest mirror vertex, the hits win: near = (1 - 1e-3) * (nearest hit depth), the mirror vertices then
//    beyond near are counted in `mirror_vertices_unclipped` and the note tells the renderer to leave the
//    element out of its own map pass.
//  - far: beyond every hit point and the scene bounding sphere if given, times (1 + far_margin).
//  - sides: the frustum contains every reflection segment [o_i, h_i] between near and far: each segment is
//    clipped to near <= z <= far, its end points are projected onto the near plane (a segment projects to a
//    segment, so the box of the end points contains it), the bounding box is widened by `margin` of its size
//    on each side, and each side is limited to max_fov_rad / 2 from `forward`. The frustum is asymmetric
//    whenever the rays are. Hits that then project outside [0, 1]^2 are counted in `hits_outside`.
//  - up: the up hint projected perpendicular to forward (paper 4.3: a principal curvature direction of a
//    saddle or cylindrical mirror aligns the map's aspect ratio with the spread of the rays; pass the mean
//    surface normal for a mirror-aligned frame), else world_up projected, else the world axis least aligned
//    with forward. right = forward x up.
//
// Reversed volume (buildReversedViewVolume), for the zooming region. Those hits lie between the eye and the
// mirror: each ray runs from o_i (the mirror, far from the eye) through h_i towards the eye. Looking from the
// eye back towards the mirror (forward' = -mean direction of the zooming rays, depth' = (p - e) . forward'),
// the point a reflection ray meets FIRST is the one nearest the mirror, i.e. the FARTHEST from the eye along
// the view line. So the renderer must:
//   1. clear the depth buffer to 0 (glClearDepth(0)) and use glDepthFunc(GL_GREATER) (paper 7: "reverse the
//      evaluation function of the depth buffer"): the fragment farthest from the eye survives;
//   2. rely on the FAR plane to remove the mirror and everything behind it: far' = min over ALL mirror
//      vertices of the patch of depth'(o_i) - gap (otherwise the mirror, being the farthest surface, would
//      win everywhere). Do not draw the element itself or its housing in this pass; anything that lies
//      between the hits and the mirror but off the rays (a housing rim) would otherwise also win;
//   3. near' = reversed_near_fraction * (nearest zooming hit depth'): objects nearer than that are clipped,
//      which costs nothing, since with GL_GREATER they would lose to anything farther on the same view line,
//      and it buys depth precision where it matters (a perspective depth buffer resolves ~z^2/near, and the
//      surfaces to discriminate lie near far');
//   4. use the same projectToTexture() with this volume for the zooming vertices. The map is not mirrored
//      for the renderer: every vertex gets its own texture coordinate. Triangles that mix zooming and
//      ordinary vertices need both maps (or a split) and are the renderer's choice.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/method/viewpoint.h"

namespace pvrr {

// The clip planes a clip-space point lies outside of, one bit each (x < -w, x > w, y < -w, y > w, z < -w,
// z > w), as GL clips: a convex hull of points lies entirely outside the volume only when the AND of their
// outcodes is not zero.
inline unsigned clipOutcode(const Vec4& c) {
  return unsigned(c.x < -c.w) | unsigned(c.x > c.w) << 1 | unsigned(c.y < -c.w) << 2 | unsigned(c.y > c.w) << 3 |
         unsigned(c.z < -c.w) << 4 | unsigned(c.z > c.w) << 5;
}

// Whether near clipping by the perspective `view_proj` can cut open a convex solid inside a box [lo, hi] within
// the view. It cannot when the box lies wholly beyond the near plane, or farther from the centre of projection
// than every point of the near plane's rectangle in the frustum: every ray from the centre then meets such a
// solid, if at all, only beyond the near plane. Built once per pass. The margins (1e-6 of the distances and
// of the box's size and place) cover float rounding on the GPU; pass camera-relative coordinates (the
// renderer's).
class NearClip {
 public:
  explicit NearClip(const Mat4& view_proj);
  bool cannotOpen(const Vec3& lo, const Vec3& hi) const;

 private:
  Mat4 view_proj_;
  Vec3 centre_{0};
  double reach_ = -1;  // the near rectangle's farthest corner from the centre; < 0: no finite centre
};

// Whether a triangle whose counter-clockwise normal points to the centre of projection of `view_proj` appears
// counter-clockwise in window space (GL_CCW front faces). False for a projection that mirrors the image.
bool facingTrianglesWindCounterClockwise(const Mat4& view_proj);

// The order in which to draw the solids inside the boxes [lo, hi] (relative to the centre of projection) so
// that the early depth test rejects the fragments of hidden ones instead of shading them: nearest first, by
// the distance to each box's nearest point (for a box around the centre, such as a room around the eye, to
// its nearest face), or with reversed depth (the farther fragment wins) farthest first, by the distance to
// each box's farthest corner. Stable: boxes with equal keys keep their given order. The picture changes only
// where two solids tie in depth.
std::vector<size_t> depthSortedDrawOrder(const std::vector<std::array<Vec3, 2>>& boxes, bool reversed_depth);

struct ViewVolume {
  Vec3 eye{0}, forward{0, 0, -1}, up{0, 1, 0}, right{1, 0, 0};  // orthonormal, right = forward x up
  double near_m = 0, far_m = 0;  // depths along forward, 0 < near_m < far_m
  // Frustum extents AT the near plane (m, in the camera's right/up coordinates), asymmetric in general:
  // left < right_, bottom < top, glFrustum(left, right_, bottom, top, near_m, far_m).
  double left = 0, right_ = 0, bottom = 0, top = 0;
  Mat4 view{1.0};           // world -> camera
  Mat4 view_relative{1.0};  // (p - eye) -> camera: the rotation only, for camera-relative rendering
  Mat4 projection{1.0};     // camera -> clip (OpenGL, NDC z in [-1, 1])
  double fov_x_rad = 0, fov_y_rad = 0;  // full angles between opposite sides
  bool reversed = false;  // forward volume: some hits lie behind the eye (zooming): render them with
                          // buildReversedViewVolume
  bool backward = false;  // this IS the reversed volume: depth test GL_GREATER, clear depth 0
  std::vector<int> zooming;  // indices of the rays whose hit lies behind the eye along the patch's forward
  int hits_covered = 0;      // hits this volume projects (forward: the others; reversed: the zooming ones)
  int hits_outside = 0;      // of those, hits that project outside [0, 1]^2 (max_fov_rad limit)
  int mirror_vertices_unclipped = 0;  // mirror vertices the near (forward) / far (reversed) plane fails to clip
  // Forward volume whose near plane could not be placed beyond the mirror (mirror_vertices_unclipped > 0): a
  // plane (n, d) in world space, n unit, with the mirror's vertices on its positive side (it passes just behind
  // the rearmost one) and what they hit farther along n than every vertex: dot(n, p) + d > 0 along every vertex
  // ray's segment. The renderer clips what lies on its negative side (behind the mirror) in the map's
  // environment pass (gl_ClipDistance). Absent when the near plane clips the mirror, or when the hits are not
  // all beyond every vertex along n (n: the plane of three ray origins spanning the largest triangle).
  // applyEyeSide (eye_side.h) drops it again for a mirror patch where it clips nothing inside the map.
  std::optional<Vec4> clip_plane;
  std::string note;  // "" or what was unusual and what the renderer must do about it
};

struct ViewVolumeOptions {
  std::optional<Vec3> up_hint;  // e.g. a principal curvature direction (paper 4.3)
  Vec3 world_up{0, 1, 0};       // the scene's up (pvrr::Observer's default)
  double margin = 0.02;         // fraction of the frustum's width/height added on each side
  double max_fov_rad = radians(150.0);  // each side at most half of this from forward
  double near_gap_m = 1e-3;     // near plane this far beyond the farthest mirror vertex (or half the gap)
  double min_near_fraction = 1e-2;       // near >= this * nearest hit depth
  double far_margin = 0.01;     // far = (1 + far_margin) * the farthest depth to contain
  Vec3 scene_center{0};         // scene bounding sphere; scene_radius_m = 0: none
  double scene_radius_m = 0;
  double reversed_near_fraction = 0.5;  // reversed volume: near' = this * nearest zooming hit depth'
};

// Throws pvrr::Error when rays is empty, the eye or a ray is not finite, or the ray directions cancel out
// (spread over more than a hemisphere: split the patch, paper 4.1). When every hit lies behind the eye the
// volume is a nominal one (note says so, hits_covered = 0).
ViewVolume buildViewVolume(const Vec3& eye, const std::vector<ViewpointRay>& rays,
                           const ViewVolumeOptions& options = {});

// The backward-looking volume for the zooming rays of the SAME rays (all of the patch's rays are needed: every
// mirror vertex must lie beyond its far plane). Throws pvrr::Error when no hit lies behind the eye.
ViewVolume buildReversedViewVolume(const Vec3& eye, const std::vector<ViewpointRay>& rays,
                                   const ViewVolumeOptions& options = {});

// (s, t) = (NDC.xy + 1) / 2 of a world point; equal to the projection * view route. NaN for points with
// depth <= 0 (at or behind the eye plane).
Vec2 projectToTexture(const ViewVolume& vv, const Vec3& world_point);
// Texel space of a width x height map: (s * width, t * height); texel (i, j) covers [i, i+1) x [j, j+1) and
// its centre is (i + 0.5, j + 0.5); row j = 0 is the bottom row.
Vec2 projectToTexel(const ViewVolume& vv, const Vec3& world_point, int width, int height);

// The texels a map of this volume needs so that its texels are square on the near plane (the same angle
// across and up the map at its centre): the longer side gets `longest_side` texels, the shorter side its
// proportional share, rounded up and at least min(longest_side, 16). A square map of an oblong frustum spends
// texels on the narrow axis that no screen pixel resolves (the spectacle lens's 108 x 79 degree frustum at
// 1280 x 720: 41 % of a square map's texels). {w, h}.
std::array<int, 2> mapTexels(const ViewVolume& vv, int longest_side);

// The longer side of a map of this volume that holds `texels_per_pixel` texels for each of `pixels` image
// pixels (mapTexels' w * h >= texels_per_pixel * pixels), rounded up to a multiple of 32 and at least 128,
// unless capped at max_side (returned as it is). texels_per_pixel <= 0: max_side.
int mapSideForPixels(const ViewVolume& vv, double pixels, double texels_per_pixel, int max_side);

// Map reuse across frames (renderer, render.map_reuse_margin_deg): a map rendered for a slightly wider view
// than the frame needs serves the next frames for as long as their views stay inside it.
//
// A copy of a forward volume with each of its four sides turned outwards by margin_rad (each side kept
// within max_fov_rad / 2 of forward) and its far plane times far_factor (>= 1). The near plane, frame and
// eye are kept. A backward (reversed) volume is returned unchanged: its far plane is what clips the mirror.
ViewVolume widenViewVolume(const ViewVolume& vv, double margin_rad, double max_fov_rad = radians(150.0),
                           double far_factor = 1.1);
// Whether `inner`'s frustum lies inside `outer`'s sides and before its far plane: each of inner's eight
// corners, projected by outer's camera, lies in front of it with |x|, |y| <= w (and z <= w for the far
// corners). Outer's near plane is not checked (both lie just beyond the element).
bool frustumContains(const ViewVolume& outer, const ViewVolume& inner);
// The longer frustum extent on the near plane over the near distance (a tangent): the map's longer side
// spans this, so texels per unit of it measure the map's sampling density.
double longerExtentTan(const ViewVolume& vv);
// The smallest angle (rad) one texel of a map of vv with `longest_side` texels (square texels, mapTexels)
// subtends as seen from its eye: at the frustum corner farthest from forward, where a tangent step spans
// the least angle (d angle = d tan * cos^2).
double minTexelAngle(const ViewVolume& vv, int longest_side);

// m as 16 doubles, row-major (out[4 * row + col]), e.g. for printing or row-major APIs; glm is column-major.
std::array<double, 16> rowMajor16(const Mat4& m);

}  // namespace pvrr

// Every frame checks itself, in envmap and impostor modes too (issue 26 item 3): the cube maps from each
// element's centre, what they can hold and what each mode makes of them, measured on the CPU at the element's
// vertices against the exact rays, with a verdict per element (ElementFrame::quality) in the stats and on the
// command line, as pvrr mode has (pvrr/method/frame_quality.h).
//
//  - The cube's near plane (cubeNearPlane): half the distance from the cube's centre to the nearest surface
//    it draws, so that nothing is clipped, and at least 1 mm. A fixed 1 mm plane left a 32-bit float depth
//    buffer unable to order surfaces 10 km away (a 100 m mirror at 10 km: 7339' median in impostor mode).
//  - Distance-map precision (both modes): the depth buffer resolves distance d to about
//    2^-24 d (far - near) / (far near) of d; beyond the limit the cube's visibility, and so what it shows,
//    is unreliable.
//  - Envmap mode: the parallax of the cube's centre. The mode shows, for each outgoing ray, the point the
//    cube sees in the ray's direction from its own centre; at each seen vertex the angle between that point
//    and the exact ray's hit, seen from the ray's origin, is the mode's error there.
//  - Envmap mode, a mirror's normals: interpolated between the vertices, so a triangle that spans much of
//    the surface's normals reflects far from the exact direction inside it (pvrr mode's same limit).
//  - Envmap mode, a lens seen from behind: its vertex rays enter the lens through its front surface (as pvrr
//    mode's did), so the picture is wrong there; flagged.
//  - Envmap mode, a lens at render.max_depth 1: the reference's paths end at its back surface (black); the cube
//    lookup draws the scene through it (measured: 6902 of 6912 such pixels lit, the spectacle lens at 96 x 72).
//  - Impostor mode, surfaces the layers cannot hold: a seen vertex's ray meets a surface that lies, as seen from
//    the cube's centre, behind as many drawn surfaces as the distance maps have layers (render.impostor_layers);
//    the search finds no surface behind every layer and shows the sky there. Counted with the exact rays, against
//    the scene's layer count (a renderer short of texture units holds fewer: then it undercounts).
//  - Impostor mode: fragments whose search ended off every layer of the distance maps (the second pass counts
//    them, noteUnresolvedSearches).
#pragma once
#include <string>
#include <vector>

#include "pvrr/method/frame_quality.h"
#include "pvrr/scene/scene.h"

namespace pvrr {

struct ElementFrame;
class RayScene;

// The smallest near plane a cube gets (the cubes' fixed plane before).
inline constexpr double kMinCubeNear_m = 1e-3;

// The distance from `centre` to the nearest environment triangle of the scene and to the nearest triangle of
// `elements` (world positions and their grid's triangles; the elements the cube draws, not its own): exact
// point-triangle distances. +inf when there is nothing.
double nearestSurface(const Scene& scene, const Vec3& centre, const std::vector<const ElementFrame*>& elements);

// Half of `nearest` (a point at distance d from the cube's centre lies at least d / sqrt(3) along a face's
// axis, so nothing is clipped), at least kMinCubeNear_m.
double cubeNearPlane(double nearest);

// The cube's far plane for element e (as drawn since the cubes exist: twice the scene's extent from the centre).
double cubeFarPlane(const Scene& scene, const Vec3& centre);

// The depth buffer's relative resolution of distance d (32-bit float depth, standard perspective).
double relativeDepthResolution(double near_m, double far_m, double d);

struct CubeQualityLimits {
  // Envmap mode: a median parallax error at the seen vertices above this is flagged (a wrong picture is a
  // median of 60' in pixels; the vertices sample the same surface).
  double max_parallax_median_arcmin = 30.0;
  // Envmap mode interpolates the vertex normals across each triangle (pvrr mode's limit, FrameQualityLimits).
  double max_normal_spread_deg = FrameQualityLimits{}.max_normal_spread_deg;
  // The depth buffer must resolve the hits' distances to this fraction of themselves.
  double max_depth_relative = 1e-3;
  // Impostor mode: a share of the element's pixels whose search ended off the distance maps above this.
  double max_unresolved_share = 0.01;
  // Impostor mode: a share of the seen vertex rays that hit something above this, hitting it behind as many
  // surfaces as the maps have layers (from the cube's centre), is flagged. 5 %: one vertex in 20, a band of the
  // picture, where one vertex alone is an edge the pixels around it mostly resolve.
  double max_behind_layers_share = 0.05;
};

struct CubeQuality {
  int seen = 0;                    // vertices assessed (front side toward the eye, or a lens)
  double parallax_median_arcmin = 0, parallax_max_arcmin = 0;  // envmap mode only
  double max_normal_spread_deg = 0;  // envmap mode: the largest angle between two corners' normals of a seen triangle
  double max_hit_distance_m = 0;   // the farthest finite hit from the cube's centre
  double depth_relative = 0;       // relativeDepthResolution at that distance
  int lens_back_vertices = 0;      // a lens's seen vertices whose front faces away from the eye
  int hit_vertices = 0;            // impostor mode: seen vertices whose ray hits a surface
  int behind_layers_vertices = 0;  // of those, hitting it behind render.impostor_layers surfaces from the centre
};

// Assesses element f's cube (centre: the element's anchor) for `mode` (envmap or impostor) with near and far
// planes near_m, far_m; in_cube[m]: element m is drawn in the cube (the others are not seen from its centre).
// Traces f's vertex rays from `eye` (one channel) unless f has rays already; sets f.quality (verdict, action,
// note) and returns the measures.
CubeQuality assessCubeQuality(const RayScene& rays, ElementFrame& f, RenderMode mode, const Vec3& eye, double near_m,
                              double far_m, const std::vector<char>& in_cube, const CubeQualityLimits& limits = {});

// Impostor mode, after the second pass: `unresolved` of the element's `pixels` ended their search off every
// layer of the distance maps (the cube cannot hold what the ray meets: a surface the maps do not resolve, or
// the search ran out of steps). Over limits.max_unresolved_share the element is flagged (degraded).
void noteUnresolvedSearches(ElementFrame& f, long unresolved, long pixels, const CubeQualityLimits& limits = {});

}  // namespace pvrr

// Caustics in the reference: light tracing from the lights through the optical elements (docs/caustics.md).
//
// What it computes: the irradiance that reaches diffuse surfaces along purely specular paths light -> element
// (reflections off mirrors, refractions through lenses, total internal reflections inside them) -> diffuse
// surface, the "L S+ D" part of the light. Direct light (L D) is the shading's (pvrr/trace/shading.h), not
// counted here; light reflected by a lens surface is not followed (the tracer's lens model).
//
// Method (per directional or point light, per element, per wavelength sample):
// - Aperture: the element's surfaces, sampled on their parameter domains, are projected along the light
//   (directional: onto the plane normal to its direction; point: as tangents of the angle about the axis
//   light -> element centre); their bounding rectangle, padded by kAperturePad of its size, is the aperture.
// - Photons: side x side strata over the aperture, one photon jittered uniformly in each (a deterministic hash of
//   seed, light, element, sample and stratum: the same photons at any thread count). A directional light's
//   photon carries its irradiance x the stratum's area, and starts upstream of everything in the scene; a point
//   light's carries its intensity x the stratum's solid angle (d(tan a) d(tan b) / (1 + tan^2 a + tan^2 b)^3/2)
//   and starts at the light. A photon counts only if the first thing it meets is that element (what meets
//   something else first is direct light, or another element's photon); so occluders upstream are honoured.
// - Transport: mirrors multiply by their reflectance (a metal's conductor Fresnel reflectance per channel, or at
//   the sample's wavelength in the spectral mode), lens interfaces by the exact unpolarised Fresnel
//   transmittance 1 - R at the sample's index n(lambda) (pvrr/optics/optics.h); TIR is followed; a mirror's back,
//   a lens's edge band and the depth limit absorb. A tinted lens's glass absorbs: each segment of length L
//   inside it multiplies the photon's power by exp(-alpha_c L) per channel c (Element::absorption_per_m, from the
//   material's "internal_transmittance"); the air does not absorb.
// - Dispersion (TraceOptions' modes): off: one sample at the d line, weight (1, 1, 1); rgb: three samples at the
//   C, d, F lines, each keeping its channel; spectral: N samples with the colour-matching weights of
//   pvrr/optics/spectrum.h. Scenes without a dispersing lens (or, spectral, a tabulated metal) trace one sample.
// - Deposit (depositPhotons): the photon's ray after its last specular event meets the receiver: either the
//   scene's surfaces (the first environment hit, kept if it lies within `slab_m` of the receiver's plane and
//   inside the rectangle) or the receiver's plane alone (a virtual screen: focus sweeps). A curved receiver (a
//   mesh that is a height field over the rectangle's plane, DepositOptions::height_field) keeps every hit on its
//   mesh, projected along the plane's normal, with its power weighed by cos(theta) between the hit triangle's
//   normal and the plane's: a cell over the plane covers cell area / cos(theta) of the surface, so the map is
//   the irradiance per unit area of the surface itself. Its power is splatted
//   with a tent kernel one cell wide (bilinear weights to the four nearest cell centres; the weights sum to 1, so
//   the border cells also take their share of the photons up to half a cell outside, so that they are not
//   biased low; power is conserved except within half a cell of the border) and divided by the cell area.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pvrr/optics/spectrum.h"
#include "pvrr/scene/render_desc.h"
#include "pvrr/trace/irradiance_grid.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

struct CausticOptions {
  int photons_per_side = 256;  // strata per side of each aperture: side^2 photons per (light, element, sample)
  int max_depth = 8;           // specular events before a photon is absorbed
  DispersionMode dispersion = DispersionMode::Off;
  int spectral_samples = 16;
  uint64_t seed = 1;
  int element = -1;  // only this element's photons (-1: every element)
  bool caustic_lights_only = false;  // only the lights with Light::caustics on (the reference picture's)
};

// A photon after its last specular event: the ray it leaves on, its power, and where that ray meets the scene.
struct CausticPhoton {
  Vec3 origin{0}, direction{0};  // direction unit
  Vec3 power{0};                 // per channel (W in the scene's light units)
  double t_hit = kInf;           // distance along the ray to the first environment surface (kInf: escapes)
  int mesh = -1;                 // that surface's mesh index, or -1
  int triangle = -1;             // the hit triangle (an index into that mesh's triangles), or -1
  Vec3 hit_normal{0};            // that surface's unit geometric normal there (the triangle's; 0 when it escapes)
  int light = -1, element = -1;  // where it came from: light index, first element
  int bounces = 0;               // specular events
};

struct PhotonBundle {
  std::vector<CausticPhoton> photons;  // the photons that left their last element (absorbed ones are not kept)
  long long emitted = 0;               // photons shot over the apertures (every stratum of every sample)
  long long entered = 0;               // of them, those whose first hit was the aperture's element
  long long absorbed = 0;              // of those, absorbed (mirror back, lens edge band, depth limit)
  Vec3 entering_power{0};              // power of the entering photons (per channel): what the elements intercept
  Vec3 leaving_power{0};               // power of `photons` after Fresnel and reflectance losses
  int samples_per_photon = 1;          // wavelength samples traced per stratum
  std::vector<std::string> notes;      // (light, element) pairs skipped, with the reason
  double elapsed_ms = 0;
};

// Shoots and traces the photons of every directional and point light through every element (or
// options.element). Multithreaded (TBB); deterministic for a given seed. Throws pvrr::Error for
// photons_per_side outside [1, 8192] or an element index out of range.
PhotonBundle shootCausticPhotons(const RayScene& rays, const CausticOptions& options);

// A receiver that is one sheet of a mesh split into sheets (pvrr/method/receiver_sheets.h: a box's face, a part
// of a sphere): the sheet of each of the mesh's triangles (-1: none) and this receiver's sheet. Only photons whose
// exact hit triangle lies in the sheet land on it, so no light crosses a seam to the wrong sheet. index -1: the
// whole mesh.
struct ReceiverSheet {
  std::shared_ptr<const std::vector<int>> of_triangle;
  int index = -1;
  bool whole() const { return index < 0; }
  bool holds(int triangle) const {
    return index < 0 || (of_triangle && triangle >= 0 && size_t(triangle) < of_triangle->size() &&
                         (*of_triangle)[size_t(triangle)] == index);
  }
};

struct DepositOptions {
  enum class Mode { Surfaces, Plane };
  Mode mode = Mode::Surfaces;
  double slab_m = 1e-3;  // Surfaces: how far from the rectangle's plane a hit may lie (not height_field)
  int mesh = -1;         // Surfaces: only hits on this mesh (-1: any)
  // Surfaces: the receiver is curved, a height field over the rectangle's plane (pvrr/method/caustic_mesh.h
  // heightFieldReceivers; `mesh` must be it): every hit on `mesh` counts at any height (slab_m unused),
  // projected along the plane's normal, its power weighed by |cos| between the hit's geometric normal and the
  // plane's normal, so that each cell holds the irradiance per unit area of the surface (a cell of the plane
  // covers cell area / cos of it), not per unit area of the plane.
  bool height_field = false;
  // Surfaces: only hits on this sheet of `mesh` (a mesh split into sheets; whole by default).
  ReceiverSheet sheet;
};

struct CausticResult {
  IrradianceGrid grid;      // irradiance per cell, and the variance of its scalar estimate per cell
  long long deposited = 0;  // photons that landed inside the rectangle
  Vec3 landed_power{0};     // their power (per channel); grid.power() is this less what the kernel put outside
  long long emitted = 0;    // the bundle's emitted photons (the sample count of the estimate)
  // The relative standard error of the scalar irradiance at the brightest cell, and averaged (power-weighted)
  // over the cells above half the peak: sqrt(sum (w P)^2) / (sum w P) per cell, the estimate as if the photons
  // were independent (an upper bound for stratified photons).
  double peak_rel_stderr = 0, spot_rel_stderr = 0;
};

CausticResult depositPhotons(const PhotonBundle& bundle, const ReceiverRect& receiver, const DepositOptions& options);

// The caustic light of the reference picture (Tracer, TraceOptions::caustics; docs/caustics.md "In the
// reference picture"): the light tracer's maps over receiver windows, computed once per render, looked up at
// every diffuse hit as the raster modes look up theirs (shaders/caustic_lookup.glsl): a point within
// DepositOptions::slab_m of a window's plane and inside it gets that map's irradiance, bilinear between cell
// centres (clamped to the border cells, as GL_CLAMP_TO_EDGE), summed over the windows; the shading adds
// albedo x that irradiance (pvrr/trace/shading.h).
struct CausticReceiverMap {
  int mesh = -1;  // Scene::meshes index: only photons landing on it are deposited
  IrradianceGrid grid;
  // A curved receiver (a height field over grid.rect's plane): per cell, the surface's height over that plane
  // along its normal (m) at the cell's centre, kNoHeight where the surface does not reach it; a point counts as
  // on the receiver where its own height lies within DepositOptions::slab_m of these heights' bilinear
  // interpolation (as the irradiance's). Empty: planar, the plane itself (height 0).
  std::vector<float> height;
  ReceiverSheet sheet;  // one sheet of the mesh (whole by default): only photons hitting its triangles
};
// A height map's cells that the surface does not cover: far beyond any slab, finite so that the bilinear
// interpolation stays finite (no point within a cell of such a cell takes the map's light).
inline constexpr float kNoHeight = 1e30f;
struct CausticLightField {
  std::vector<CausticReceiverMap> receivers;
  long long emitted = 0;        // photons shot (the sample count)
  int photons_per_side = 0;     // strata per side of each aperture
  int samples_per_photon = 1;   // wavelength samples
  double elapsed_ms = 0;
  Vec3 irradianceAt(const Vec3& p) const;
};
// Shoots the photons of the lights with caustics on (options.caustic_lights_only is forced) and deposits them
// on each receiver's window, keeping the hits on its mesh (height_field where the window has heights).
CausticLightField causticLightField(const RayScene& rays, const std::vector<CausticReceiverMap>& windows,
                                    CausticOptions options);

// The padding of an aperture rectangle, relative to its size (covers the sampling of curved rims).
constexpr double kAperturePad = 0.02;

// The steps of shootCausticPhotons, shared with the raster caustics (pvrr/method/caustic_mesh.h), which trace
// the same photons at the vertices of a grid over the same aperture.

// Where the photons of one (light, element) pair come from: origin + x a + y b (+ along the axis) over the
// rectangle [x0, x1] x [y0, y1]. Directional: positions on a plane normal to the light, the origin upstream of
// the scene's bounds; point: tangents (x, y) of the angles about the unit axis light -> element.
struct CausticAperture {
  bool point = false;
  Vec3 origin{0}, axis{0}, a{0}, b{0};
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};
// False, with the reason, when the pair has none (no finite surface point, a point light within the element).
bool causticAperture(const Scene& scene, const Light& light, const Element& el, CausticAperture& ap,
                     std::string& why);
// The wavelength samples to trace: one (wavelength 0: the d line, weight 1) when nothing in the scene depends
// on the wavelength or dispersion is off.
std::vector<SpectralSample> causticSamples(const Scene& scene, const CausticOptions& o);
// The photon at aperture coordinates (x, y) carrying the power of `measure` (an area in m^2, directional; a
// tangent-plane area, point: the solid angle is measure / (1 + x^2 + y^2)^3/2) of the light at the sample.
CausticPhoton photonAt(const CausticAperture& ap, const Light& light, const SpectralSample& sample, double x, double y,
                       double measure);
enum class PhotonFate { Missed, Absorbed, Left };
// Follows one photon from its first element to the ray it leaves on: `p` holds origin, direction and power on
// entry, and on Left the ray it leaves on, its power after the element's reflectance or Fresnel transmittances,
// and where it meets the environment. Missed: its first hit is not `element`.
PhotonFate followPhoton(const RayScene& rays, int element, double wavelength_nm, bool spectral, int max_depth,
                        CausticPhoton& p);

// The automatic window of the caustic light landed on a receiver (`landed`: receiver coordinates and power):
// about the power's centroid, the square holding `quantile` of the power (its Chebyshev radius), enlarged
// `scale` times, at least `min_side_m` across. Nothing when no power landed. The raster caustic maps
// (pvrr/method/caustic_mesh.h) and `pvrr caustic` choose their windows with it.
struct PowerWindow {
  Vec2 centre{0.0};
  double side_m = 0;
};
std::optional<PowerWindow> powerWindow(const std::vector<std::pair<Vec2, double>>& landed, double quantile,
                                       double scale, double min_side_m);

}  // namespace pvrr

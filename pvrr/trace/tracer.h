// The reference: a Whitted ray tracer on the exact element surfaces, the ground truth for every accuracy
// figure. Environment shading is pvrr/trace/shading.h, the same model the raster path uses, with shadow rays
// (pvrr/trace/shadow_rays.h) for the lights whose shadows are on. A mirror's dark back is shaded unshadowed,
// as the raster path shades it.
// With render.ambient_occlusion on, the ambient lights' term of every environment hit is multiplied by its
// visibility, estimated by hemisphere sampling (pvrr/trace/ambient_occlusion.h).
//
// Lens model (shared with the raster path): light passing a lens is weighted by the exact Fresnel
// transmittance (1 - R) of each interface it crosses; the light a lens surface reflects is not added.
// Total internal reflection inside a lens is followed (up to the depth limit). A tinted lens's glass absorbs:
// each segment of length L inside it multiplies the throughput by exp(-alpha_c L) per channel c
// (Element::absorption_per_m; a spectral or rgb sample's channel weight gets the same factor). A mirror reflects with its
// reflectance (or the conductor Fresnel reflectance of its metal, per channel); its back side is dark.
//
// Dispersion (DispersionMode, pvrr/scene/render_desc.h): "off" traces one ray with each lens's index at the d
// line; "rgb" traces one ray per channel at that channel's wavelength (pvrr/optics/spectrum.h) and keeps that
// channel; "spectral" traces N wavelengths and sums them with the colour-matching weights of
// pvrr/optics/spectrum.h. A metal mirror with a measured table (MirrorMaterial::metal_table) reflects with its
// per-channel (n, k) in the off and rgb modes, and in the spectral mode with its conductor Fresnel
// reflectance at each sample's wavelength, Metal::index(lambda).
//
// Caustics: TraceOptions::caustics.
//
// Primary rays: render() intersects the primary rays of 4 x 4 pixel tiles as Embree packets
// (RayScene::intersectPacket, the same exact hits as single rays); every secondary ray is a single ray.
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "pvrr/base/frame.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/scene/render_desc.h"

namespace pvrr {

struct CausticLightField;  // pvrr/trace/light_tracer.h

// One segment of a traced path (pvrr trace prints these). The segment runs from `origin` along `direction`
// to its event point.
struct PathSegment {
  Vec3 origin{0}, direction{0};
  std::string event;       // reflect | refract | tir | diffuse | escape | absorb (depth limit, mirror back)
  int element = -1;
  bool has_point = false;
  Vec3 point{0}, normal{0};
  double n1 = 1, n2 = 1;   // refractive indices before and after (refract, tir); 1 otherwise
};

struct TraceResult {
  Vec3 color{0};           // linear RGB
  Vec3 seen{0};            // the final diffuse hit, or o + far * d for an escaping ray
  bool escaped = false;
  int first_element = -1;  // the first optical element the path met
  Vec3 element_point{0};   // where it met it
  int bounces = 0;         // specular events (reflections, refractions, TIRs)
  bool depth_limited = false;  // the path ended at the depth limit on an element (no seen point; black)
  bool hit_lens = false;   // the path crossed a lens (the wavelength changes the path)
  bool hit_metal = false;  // the path reflected off a mirror with a metal table (the wavelength changes
                           // its spectral-mode colour, not its path)
};

struct TraceOptions {
  int max_depth = 8;
  DispersionMode dispersion = DispersionMode::Off;
  int spectral_samples = 16;
  bool primary_packets = true;  // render(): primary rays of 4 x 4 tiles as packets (false: one ray each)
  // The caustic light (docs/caustics.md "In the reference picture"), computed once by the caller and kept alive
  // while the tracer runs: added at every diffuse hit (albedo x its irradiance), and for the lights with
  // caustics on a lens blocks their shadow rays fully (ShadowRays' caustic_lights_block), since their light
  // through it is the caustic. Null: no caustic light, lenses pass every light (Fresnel), as before.
  const CausticLightField* caustics = nullptr;
};

class Tracer {
 public:
  Tracer(const RayScene& rays, TraceOptions options);

  // One ray at one wavelength (nm; <= 0 means the design wavelength, the d line). Optionally records the path.
  TraceResult trace(const Vec3& o, const Vec3& d, double wavelength_nm, std::vector<PathSegment>* path = nullptr) const;
  // A full pixel (pixel coordinates with centres at +0.5, origin top-left) honouring the dispersion mode.
  TraceResult tracePixel(double px, double py) const;
  // The whole image, multithreaded (TBB) with FTZ/DAZ per thread: every buffer of the Frame (channel_seen in
  // the rgb dispersion mode only), and its one stage "ray-trace". `progress` (fraction done) is called from
  // one thread at a time, at most every few rows.
  Frame render(const std::function<void(double)>& progress = {}) const;

 private:
  // `first`: the hit of the ray (o, d) for t > 0 when already known (a packet's lane), else null.
  // `metal_spectral`: a metal mirror with a table reflects with its Fresnel reflectance at `wavelength_nm`
  // in all three channels (a spectral-mode sample) instead of its per-channel (n, k).
  TraceResult traceImpl(const Vec3& o, const Vec3& d, double wavelength_nm, std::vector<PathSegment>* path,
                        const RayHit* first, bool metal_spectral) const;
  // A pixel whose primary ray is `d` from the eye, honouring the dispersion mode; `channel_seen` (Rgb mode,
  // optional) receives each channel's seen point.
  TraceResult tracePrimary(const Vec3& d, const RayHit* first, std::array<Vec3, 3>* channel_seen) const;

  const RayScene& rays_;
  const Scene& scene_;
  TraceOptions options_;
  std::vector<SpectralSample> spectral_;  // the spectral mode's wavelengths and weights, computed once
};

}  // namespace pvrr

// The environment shading model, shared by the reference tracer (this code) and the raster path
// (shaders/shading.glsl implements the same formulas; keep them in step).
//
//   colour = albedo(uv) * ( sum ambient  +  sum_directional max(0, n.(-dir)) L  +  sum_point max(0, n.l) L / d^2 )
//
// n is the geometric normal turned towards the viewer (two-sided). With `shadows` given, each directional
// and point light's term is multiplied by its transmittance to p (pvrr/trace/shadow_rays.h; 1 for a light
// with shadows off); the raster path multiplies by its shadow maps' estimate of the same
// (shaders/shadow_lookup.glsl). `caustic` is the caustic irradiance at p (W/m^2 per channel,
// pvrr/trace/light_tracer.h CausticLightField), added to the light as env.frag adds it:
// albedo * (light + caustic). Colours are linear RGB; textures are decoded
// from sRGB before bilinear filtering with repeat wrapping (what GL does for GL_SRGB8 + GL_LINEAR).
#pragma once
#include "pvrr/scene/scene.h"
#include "pvrr/trace/shadow_rays.h"

namespace pvrr {

// Albedo of a mirror's dark back (its housing), shaded as a diffuse surface; the tracer's and the shaders'
// (MIRROR_BACK_ALBEDO, injected by pvrr/gl/program.cpp cppConstantsSource).
inline constexpr double kMirrorBackAlbedo = 0.05;

Vec3 sampleTexture(const Texture& t, Vec2 uv);
// ambient_visibility: the ambient lights' term is multiplied by it (ambient occlusion,
// pvrr/trace/ambient_occlusion.h; 1 without).
Vec3 shadeDiffuse(const Scene& scene, const DiffuseMaterial& m, const Vec3& p, const Vec3& n_facing, Vec2 uv,
                  const ShadowRays* shadows = nullptr, double ambient_visibility = 1.0,
                  const Vec3& caustic = Vec3(0.0));

}  // namespace pvrr

// Shadow maps (stage "shadow-maps"): for every directional and point light whose shadows are on
// (Light::shadows), depth maps rendered from the light, which the environment's shading reads in every pass
// (the second pass and the first passes: pvrr maps, envmap and impostor cubes), so that a shadow seen in a
// mirror is the shadow seen directly (shaders/shadow_lookup.glsl).
//
// - A directional light: one orthographic map along the light, fitted to the scene's bounding sphere.
// - A point light: six perspective maps, one per axis direction, each a little wider than 90 degrees so that
//   the filter's taps near a face's edge stay on that face.
// All maps are the layers of one GL_TEXTURE_2D_ARRAY of depths, compared in hardware (sampler2DArrayShadow)
// and filtered as 3 x 3 bilinear taps one texel apart (PCF over a 4 x 4 texel footprint, read by four
// gathers; measured in docs/accuracy.md "Shadows", its cost in docs/performance.md "Shadows").
// Casters: the environment meshes and the mirrors (opaque); the lenses go into their own depth layers with
// their transmittance beside, per channel (RGBA16F): (1 - R0)^2, times a tinted lens's absorption along the
// straight chord through its glass towards the light, per caster vertex (cad::chordInside; the reference's
// shadow rays take the same chord at each point, pvrr/trace/shadow_rays.h): a point behind the nearest lens from the
// light gets that lens's transmittance, behind an opaque caster nothing; for a light whose caustics are on
// (pvrr/gl/caustic_pass.h) nothing either, as the light through the lens arrives as the caustic. The maps are
// rendered when the
// renderer's first frame needs them and again when something they show may have changed:
// FrameCache::environment_changed (the caller's, or the renderer's when an animated mesh moved), as for the
// cube maps (pvrr/gl/cube_pass.h), or an element or an animated mesh moved (pvrr/scene/scene_poses.h, the
// one test of what moved that the cube maps use too). Without a frame cache only the poses decide (the
// environment otherwise stands still); the lights stand still.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/stats.h"
#include "pvrr/gl/gl_objects.h"
#include "pvrr/gl/programs.h"
#include "pvrr/method/pass_plan.h"
#include "pvrr/scene/scene.h"
#include "pvrr/scene/scene_poses.h"

namespace pvrr::gl {

class EnvironmentPass;

inline constexpr const char* kShadowMapsStage = "shadow-maps";

// The layers each light takes: per light of the scene, its first layer, or -1 (no shadows: ambient, or off).
struct ShadowLayout {
  std::vector<int> first_layer;
  int layers = 0;
  bool lenses = false;  // the scene has a lens: lens layers too
};
ShadowLayout shadowLayout(const Scene& scene);
// The defines of an environment program that reads the maps (SHADOWS, SHADOW_LAYERS, SHADOW_LENSES); none
// when no light casts shadows.
std::vector<std::string> shadowDefines(const Scene& scene);

class ShadowPass {
 public:
  // The map side (texels) of every layer.
  static constexpr int kMapSize = 1024;

  // The maps' units are units::shadowMaps and the two after it (pvrr/gl/texture_units.h), as
  // GL_TEXTURE_2D_ARRAY bindings, which no other program of the renderer samples there.
  ShadowPass(const Scene& scene, const Programs& programs, const EnvironmentPass& environment, int max_texture_units);
  ~ShadowPass();
  ShadowPass(const ShadowPass&) = delete;
  ShadowPass& operator=(const ShadowPass&) = delete;

  // Renders the maps if they are missing or may show something else (see above); notes the stage (ran with
  // why, reused, or skipped with the reason).
  void update(FrameStages& stages, const FrameCache* cache);
  bool active() const { return layout_.layers > 0; }
  // Binds the maps to their units and sets program p's shadow uniforms for a pass whose camera origin is
  // `origin`. Nothing when no light casts shadows.
  void bind(const Program& p, const Vec3& origin) const;

 private:
  struct Layer {
    Mat4 view{1.0}, proj{1.0};
    Vec3 origin{0};      // the light camera's origin (camera-relative rendering)
    double texel_m = 0;  // a texel's size at unit distance (point) or everywhere (directional), metres
    bool perspective = false;
    double near_m = 0, far_m = 0;  // point: the depth range
    bool caustics = false;         // the light's caustics are on: a lens passes none of its light straight
    size_t light = 0;              // its light in Scene::lights
  };
  // A tinted lens's caster for one light: its front surface with each vertex's chord through the glass along
  // that light (cad::chordInside), remade when the light's direction (or position) in the lens's frame moved.
  struct ChordCaster {
    MeshBuffers mesh;
    Vec3 light_local{0};  // the light's direction (directional) or position (point) in the lens's frame
    bool made = false;
  };
  const MeshBuffers& tintedCaster(size_t element, size_t light);
  void makeLayers();
  void makeTextures();
  void render();
  // Why the maps must be drawn this frame, or "" when the last ones serve.
  std::string staleReason(const FrameCache* cache) const;

  const Scene& scene_;
  const Programs& programs_;
  const EnvironmentPass& environment_;
  ShadowLayout layout_;
  std::vector<Layer> layers_;
  int unit_ = 0;  // the depth maps' unit; the lens depths and transmittances on the two after it
  unsigned depth_ = 0, lens_depth_ = 0, lens_t_ = 0, fbo_ = 0;
  std::vector<MeshBuffers> element_meshes_;  // per element: its front surface, element-local
  std::vector<std::vector<Vec3>> caster_points_;        // per tinted lens: those vertices (else empty)
  std::vector<std::vector<ChordCaster>> chord_casters_;  // per tinted lens and light
  std::vector<std::vector<uint32_t>> caster_indices_;    // per tinted lens: its caster's triangles
  ScenePoses rendered_poses_;                // what the maps were rendered with
  bool rendered_ = false;
};

}  // namespace pvrr::gl

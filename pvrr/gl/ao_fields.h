// Ambient occlusion in every raster pass (render.ambient_occlusion; stage "ambient-occlusion"): the
// displacement fields of the occluding objects (pvrr/method/ao_field.h) and the occlusion volumes evaluated
// from them, precomputed on the CPU when the renderer is made; the volumes are uploaded once as one RGBA8
// GL_TEXTURE_3D (two blocks of slices per occluder); the environment's
// shading reads them in every pass (the second pass and the first passes: pvrr maps, envmap and impostor
// cubes), so that a car's ground shadow seen in a mirror is the one seen directly
// (shaders/ambient_occlusion.glsl). Each field follows its object's current rigid motion (EnvMesh::motion),
// uploaded per pass, so an animated car keeps its occlusion.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/stats.h"
#include "pvrr/gl/programs.h"
#include "pvrr/method/ao_field.h"
#include "pvrr/scene/scene.h"

namespace pvrr::gl {

inline constexpr const char* kAmbientOcclusionStage = "ambient-occlusion";

// Why the scene's shading has no ambient occlusion, or empty when it has: off, no occluding object, or no
// ambient light to occlude.
std::string ambientOcclusionSkipReason(const Scene& scene);
// The defines of an environment program that reads the fields (AMBIENT_OCCLUSION, AO_FIELDS,
// AO_POSITIONS, AO_DIRECTIONS, AO_SIDE); none when the scene has no ambient occlusion.
std::vector<std::string> aoDefines(const Scene& scene);

class AoFields {
 public:
  // Builds and uploads the fields (nothing when ambientOcclusionSkipReason is not empty). Their unit is
  // units::aoVolume (pvrr/gl/texture_units.h).
  AoFields(const Scene& scene, int max_texture_units);
  ~AoFields();
  AoFields(const AoFields&) = delete;
  AoFields& operator=(const AoFields&) = delete;

  bool active() const { return texture_ != 0; }
  // Binds the fields and sets program p's uniforms for a pass whose camera origin is `origin`.
  void bind(const Program& p, const Vec3& origin) const;
  // The occluder the next draw belongs to (EnvMesh::occluder; it does not occlude itself), or -1.
  void setReceiver(const Program& p, int occluder) const;
  // Notes the stage: the fields' count, size and precomputation time (once: "built"; later frames: "reused").
  void note(FrameStages& stages) const;
  const std::vector<AoField>& fields() const { return fields_; }

 private:
  const Scene& scene_;
  std::vector<AoField> fields_;
  int unit_ = 0;
  unsigned texture_ = 0;
  double build_ms_ = 0;
  size_t volume_bytes_ = 0;
  mutable bool noted_ = false;
};

}  // namespace pvrr::gl

// Ambient occlusion in every raster pass (render.ambient_occlusion; stage "ambient-occlusion"): the
// displacement fields of the occluding objects (pvrr/method/ao_field.h) and the occlusion volumes evaluated
// from them, precomputed on the CPU when the renderer is made; the volumes are uploaded once as one RGBA8
// GL_TEXTURE_3D (two blocks of slices per occluder); the environment's
// shading reads them in every pass (the second pass and the first passes: pvrr maps, envmap and impostor
// cubes), so that a car's ground shadow seen in a mirror is the one seen directly
// (shaders/ambient_occlusion.glsl). Each field follows its object's current rigid motion (EnvMesh::motion),
// uploaded per pass, so an animated car keeps its occlusion.
//
// What a draw pays (llvmpipe shades both sides of every per-fragment branch, so the choice is made per draw,
// by program variant: AoReceiver). A faceted mesh is drawn plane by plane (a box's faces;
// pvrr/gl/environment_pass.h), each with the fields whose volume can cast kAoNegligible on it with its one
// normal (volumeBound: a face turned away from every car, such as the inner face of a door, has none); other
// meshes with the fields whose reach their box meets. What no field counts for is drawn without ambient
// occlusion. Of the rest, a horizontal plane facing up (grounds, pavements: static, not an occluder, every
// normal vertical, one height) is evaluated from the ground maps (pvrr/method/ao_field.h groundMap: one
// bilinear lookup per occluder) while every occluder turns about the vertical only, anything else from the
// volumes. A face that is a rectangle (static or moving) is drawn instead as a grid whose vertices hold its
// occlusion (AoReceiver::Vertex, pvrr/gl/ao_vertex_receivers.h: no texture read per fragment). Of what cannot be
// tessellated so, static receivers are evaluated only into the pass's low-resolution occlusion image, which their
// fragments read (AoReceiver::Screen); moving ones evaluate the fields per fragment.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pvrr/base/stats.h"
#include "pvrr/gl/ao_vertex_receivers.h"
#include "pvrr/gl/programs.h"
#include "pvrr/method/ao_field.h"
#include "pvrr/scene/scene.h"

namespace pvrr::gl {

inline constexpr const char* kAmbientOcclusionStage = "ambient-occlusion";

// Why the scene's shading has no ambient occlusion, or empty when it has: off, no occluding object, or no
// ambient light to occlude.
std::string ambientOcclusionSkipReason(const Scene& scene);
// The defines of an environment program that reads the fields (AMBIENT_OCCLUSION, AO_FIELDS, AO_VOLUME,
// AO_PER_VERTEX; Ground: AO_GROUND, AO_HEIGHTS); none when the scene has no ambient occlusion or for AoReceiver::None.
std::vector<std::string> aoDefines(const Scene& scene, AoReceiver receiver = AoReceiver::Volume);

// Sets the bound texture of `target` (GL_TEXTURE_2D, _2D_ARRAY, _3D): linear filtering, clamped at its edges
// (along r too for a 3D texture), one level.
void linearClampedOneLevel(unsigned target);

class AoFields {
 public:
  // Builds and uploads the fields (nothing when ambientOcclusionSkipReason is not empty). Their unit is
  // units::aoVolume (pvrr/gl/texture_units.h).
  AoFields(const Scene& scene, int max_texture_units);
  ~AoFields();
  AoFields(const AoFields&) = delete;
  AoFields& operator=(const AoFields&) = delete;

  bool active() const { return texture_ != 0; }
  // The texture unit of the fields (and of a pass's low-resolution occlusion image, on its GL_TEXTURE_2D target).
  int unit() const { return unit_; }
  // Binds the fields and sets program p's uniforms for a pass whose camera origin is `origin`.
  void bind(const Program& p, const Vec3& origin) const;
  // How a draw of environment mesh m (or of the part of it whose box in world coordinates is `world_box`) is
  // occluded now (the occluders' current motion): its variant and, per field, whether the field is weighted.
  // `facing`: the one normal the shader uses over that part (a plane face, turned to the viewer), or null.
  // With a normal, a field counts where its volume's occlusion for that normal, fade included, can reach
  // kAoNegligible somewhere in the box (volumeBound); without, where the box is within the field's reach.
  // None when no field counts or the fields are not active.
  struct Draw {
    AoReceiver kind = AoReceiver::None;
    std::vector<float> reaches;  // per field: 1 counted, 0 not (its own occluder's: 0)
    bool operator==(const Draw& o) const { return kind == o.kind && reaches == o.reaches; }
  };
  Draw receiver(size_t m, const std::array<Vec3, 2>& world_box, const Vec3* facing = nullptr) const;
  // Sets program p's uniforms for such a draw of environment mesh m: the fields counted, its ground maps' height.
  void setReceiver(const Program& p, size_t m, const Draw& d) const;
  // The most occlusion field f's volume, fade included, casts at a point of world box `box` with unit normal n
  // (world), its object where it is now: the largest grid value of the channels n reads over the cells the
  // box's bounds in the field's frame touch, times the fade at the box's nearest point. Conservative.
  double volumeBound(const AoField& f, const std::array<Vec3, 2>& box, const Vec3& n) const;
  // Notes the stage: the fields' count, size and precomputation time (once: "built"; later frames: "reused").
  void note(FrameStages& stages) const;
  const std::vector<AoField>& fields() const { return fields_; }
  // The faces drawn with vertex values (a cache of grids made on first use, remade when something moves;
  // null when the fields are not active).
  AoVertexReceivers* vertexReceivers() const { return receivers_.get(); }

 private:

  const Scene& scene_;
  std::vector<AoField> fields_;
  int unit_ = 0;
  unsigned texture_ = 0;
  unsigned ground_texture_ = 0;      // GL_TEXTURE_2D_ARRAY, R8: per field one layer per height
  std::vector<double> heights_;      // the horizontal planes' heights (world y), AO_HEIGHTS of them
  std::vector<int> mesh_height_;     // per environment mesh: its index in heights_, or -1 (not such a plane)
  double build_ms_ = 0;
  size_t volume_bytes_ = 0, ground_bytes_ = 0;
  mutable bool noted_ = false;
  std::unique_ptr<AoVertexReceivers> receivers_;
};

}  // namespace pvrr::gl

// Build: the validated plain description (pvrr/scene/scene_desc.h) -> the runtime Scene (pvrr/scene/scene.h).
// Environment meshes from files are read by a loader the caller provides (the app reads OBJ and PLY with
// VTK, which pvrr/ does not depend on).
#pragma once
#include <functional>
#include <optional>
#include <string>

#include "pvrr/scene/scene.h"
#include "pvrr/scene/scene_desc.h"

namespace pvrr {

// A run of a mesh file's triangles with a material of its own (a glTF primitive): the file's material
// replaces the scene object's material for these triangles (docs/scene-format.md, environment meshes).
struct MeshPart {
  std::string name;
  size_t first_triangle = 0, triangle_count = 0;
  Vec3 base_color{1};              // linear RGB albedo (glTF's base colour factor)
  std::optional<Texture> texture;  // glTF's base colour texture (sRGB RGB8, rows top-down), multiplied by it
};

// Reads a mesh file: positions in file coordinates, normals (may be empty: then computed from faces) and
// texture coordinates (may be empty; v = 0 at the bottom of a texture image, as for every pvrr texture).
struct MeshData {
  std::vector<Vec3> positions, normals;
  std::vector<Vec2> uvs;
  std::vector<glm::u32vec3> triangles;
  // Empty: the whole mesh takes the scene object's material. Otherwise the parts cover the triangles in
  // order, and each becomes an environment mesh of its own with the file's material.
  std::vector<MeshPart> parts;
};
using MeshLoader = std::function<MeshData(const std::string& path)>;

// Throws pvrr::Error naming the scene file and the element or object when something cannot be built
// (e.g. lens surfaces that cross, a CAD file without the requested face).
Scene buildScene(const SceneDesc& desc, const MeshLoader& load_mesh = {});

// The pose of an element attached to the observer follows the observer: recomputes local_to_world for
// every attached element after the observer moved (pvrr render --orbit), and of every animated element at
// scene.time_s.
void updateAttachedElements(Scene& scene, const SceneDesc& desc);

// Whether any environment object or element of the scene is animated.
bool isAnimated(const SceneDesc& desc);

// Poses the animated environment meshes (from Scene::placed_meshes, rigidly: anchor, positions and normals)
// and elements at time t_s (seconds) and sets scene.time_s; the bounds stay (they hold every key's pose).
// Returns whether any of them moved from where it was. buildScene poses the scene at t = 0.
bool applyAnimation(Scene& scene, const SceneDesc& desc, double t_s);

// Spectacle prescription -> surface radii (our sign convention, cad/sag.h). `base_curve_d` is the
// object-side surface power; t the centre thickness (m). Back vertex power = sphere (+ cylinder).
struct PrescriptionRadii {
  double back_radius_m;            // object side (the lens's "back" surface)
  double front_radius_a_m;         // eye side, along the cylinder axis (the sphere meridian)
  double front_radius_b_m;         // eye side, perpendicular (sphere + cylinder meridian)
};
PrescriptionRadii prescriptionRadii(double sphere_d, double cylinder_d, double base_curve_d, double n,
                                    double centre_thickness_m);
double defaultBaseCurve(double sphere_d);

}  // namespace pvrr

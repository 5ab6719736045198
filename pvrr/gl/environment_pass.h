// The environment in every pass: the sky and the scene's environment meshes (uploaded once, with their
// textures), drawn from any camera in camera-relative coordinates; the lights' uniforms every program shares.
#pragma once
#include <array>
#include <map>
#include <tuple>
#include <vector>

#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/gl_objects.h"
#include "pvrr/gl/occlusion_image.h"
#include "pvrr/gl/programs.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/gl/stage_notes.h"

namespace pvrr::gl {

class ShadowPass;
class CausticPass;

// The uniforms of shaders/shading.glsl, for a pass whose camera origin is `origin`.
void setLights(const Program& p, const Scene& scene, const Vec3& origin);

class EnvironmentPass {
 public:
  // Uploads the scene's textures and meshes and builds the sky's and the meshes' programs.
  EnvironmentPass(const Scene& scene, const RendererOptions& options, const Programs& programs);
  ~EnvironmentPass();
  EnvironmentPass(const EnvironmentPass&) = delete;
  EnvironmentPass& operator=(const EnvironmentPass&) = delete;

  // Sky and environment from a camera at `origin` (view and proj in world coordinates).
  // reversed_depth: the zooming-region pass (view_volume.h): the fragment farthest from the camera wins.
  // rays_from: where the viewing rays start (two-sided normals face it); the camera unless given.
  // Forward passes (not reversed_depth) draw the sky last, where the depth buffer is still clear, so that
  // no pixel is shaded twice for it; what was drawn into the target before (the elements of the second
  // pass, drawn first so that the environment behind them fails the early depth test) stays.
  // planes: into a planes map. with_seen: write seen points even when RendererOptions::seen_points is off
  // (impostor cube maps). peel: an impostor cube's second layer (the first layer's cubes bound from kPeelUnit and
  // kFirstCubeUnit).
  // With ambient occlusion, a forward pass that is not a peel first draws the static receivers' occlusion into
  // its low-resolution occlusion image (binding its own framebuffer and viewport, then restoring the caller's).
  // clip_plane (world, ViewVolume::clip_plane): the meshes are clipped where dot(n, p) + d < 0 (gl_ClipDistance[0],
  // shaders/env.vert), and no back face is culled (the plane may cut a solid open); the sky is not clipped.
  // Returns how many closed convex meshes it drew and culled.
  CullCount draw(const Mat4& view, const Mat4& proj, const Vec3& origin, bool reversed_depth = false,
                 const Vec3* rays_from = nullptr, bool planes = false, bool with_seen = false, bool peel = false,
                 const Vec4* clip_plane = nullptr) const;

  // The environment meshes as shadow casters (shaders/shadow_caster.vert; pvrr/gl/shadow_pass.h): positions
  // only, every face, into whatever target is bound; view_proj acts on points relative to `origin`.
  void drawCasters(const Program& p, const Mat4& view_proj, const Vec3& origin) const;
  // The shadow maps the meshes' shading reads in every pass (null: none). Set by the renderer.
  void setShadows(const ShadowPass* shadows) { shadows_ = shadows; }
  // The caustic light maps the meshes' shading adds (null: none). Set by the renderer.
  void setCaustics(const CausticPass* caustics) { caustics_ = caustics; }
  // The ambient occlusion fields the meshes' shading reads in every pass (null: none). Set by the renderer.
  void setAoFields(const AoFields* ao) { ao_ = ao; }
  // Whether some light casts shadows (the meshes' shading depends on where the others are).
  bool shadowed() const;
  // Whether one of meshes `moved` is an ambient occluder whose field is drawn (its occlusion reaches past
  // its own box, onto the static surfaces around it).
  bool occludes(const std::vector<size_t>& moved) const;

  // The animated meshes that moved since they were uploaded (Scene::mesh_motion): their vertex buffers are
  // written again in place (the scene holds their moved vertices) and their boxes recomputed. Returns them.
  std::vector<size_t> update();
  // Mesh m's bounding box in world coordinates, as uploaded.
  std::array<Vec3, 2> worldBox(size_t m) const;

 private:
  // The environment meshes' bounding boxes relative to `origin`.
  std::vector<std::array<Vec3, 2>> boxes(const Vec3& origin) const;
  // The order to draw them in: the scene's, or sorted by their distance (RendererOptions::sort_environment).
  std::vector<size_t> drawOrder(const std::vector<std::array<Vec3, 2>>& boxes, bool reversed_depth) const;
  // Uploads mesh m's vertices (relative to its anchor) and sets its box.
  void upload(size_t m);

  const Scene& scene;
  const RendererOptions& options;
  const Programs& programs;
  unsigned empty_vao = 0;  // the sky's triangle, made in its vertex shader
  std::vector<MeshBuffers> env_meshes;
  std::vector<bool> env_faceted;  // per environment mesh: every triangle has one normal at its three corners
  std::vector<bool> env_textured;  // per environment mesh: its material has a texture
  std::vector<std::array<Vec3, 2>> env_bounds;  // per environment mesh: its bounding box, relative to its anchor
  std::vector<Mat4> env_motion;  // per environment mesh: the Scene::meshMotion its buffers hold
  // Per environment mesh, in a scene with ambient occlusion: its triangles grouped by plane (a faceted mesh of at
  // most kMaxFaceGroups planes, such as a box's six faces), uploaded group after group, so that each part is
  // drawn with the ambient occlusion its one normal needs (AoFields::receiver): a box face turned away from
  // every car, or out of the reach of its occlusion, is drawn without. Empty: the mesh is one draw.
  struct FaceGroup {
    int first = 0, count = 0;  // its indices in the index buffer
    Vec3 normal{0};            // the planes' normal, as uploaded
    Vec3 point{0};             // a point of the plane, relative to the mesh's anchor
    std::array<Vec3, 2> box;   // its vertices' bounding box, relative to the mesh's anchor
    std::vector<uint32_t> triangles;  // its triangles (the mesh's), for its vertex-value grid (AoVertexReceivers)
  };
  std::vector<std::vector<FaceGroup>> env_groups;
  bool group_faces = false;  // the scene has ambient occlusion
  // How each mesh or face is ambient-occluded (EnvironmentPass::draw), per (mesh, face or -1, the viewer's side),
  // for the meshes' motions in ao_choices_motion.
  struct AoChoice {
    AoFields::Draw draw;
    const MeshBuffers* grid = nullptr;
    int plain = 0;  // a mesh drawn as one buffer (AoVertexReceivers::Merged): its indices drawn without the values
  };
  mutable std::map<std::tuple<size_t, int, int>, AoChoice> ao_choices;
  mutable std::vector<Mat4> ao_choices_motion;
  // The passes' low-resolution occlusion image (the static receivers' ambient occlusion).
  mutable OcclusionImage ao_image;
  std::vector<Texture> textures;  // environment textures, in Scene::textures order
  const ShadowPass* shadows_ = nullptr;
  const CausticPass* caustics_ = nullptr;
  const AoFields* ao_ = nullptr;
};

}  // namespace pvrr::gl

// Envmap and impostor modes: a cube map from each element's centre (colour and seen points; in impostor mode
// the seen points are each direction's distance, and with several elements a third cube holds the normals
// and indices of the elements drawn in it), rendered before the second pass; impostor mode's second layers
// (depth-peeled cubes at half the size), drawn within the second pass only where some pixel's search needs
// them; and each element's second-pass draw from its cubes.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pvrr/gl/impostor_maps.h"
#include "pvrr/gl/mode_pass.h"
#include "pvrr/gl/stage_notes.h"
#include "pvrr/scene/scene_poses.h"

namespace pvrr::gl {

class CubePass : public ModePass {
 public:
  explicit CubePass(const RenderContext& c) : ctx(c), maps(c.scene, c.options, c.max_texture_units) {}

  void prepare(RenderMode mode, FrameStages& stages, FrameCache* cache) override;
  std::string drawElements(RenderMode mode, const PassCamera& eye, const Framebuffer& target) override;
  // Each element's frame with its quality (pvrr/method/cube_quality.h), as drawn.
  std::vector<ElementFrame> takeElements() override { return std::move(frames); }

 private:
  // The elements drawn in other elements' cubes: the mirrors, and the lens if it is the only one.
  bool inCubes(size_t m) const;
  // Element m drawn into a face of another element's impostor cubes, from a camera at `origin` (view_proj
  // relative to it), before the environment (CUBE_GEOMETRY): a mirror's exact surface point and normal per
  // fragment, a lens's mesh.
  void drawCubeElement(size_t m, const Mat4& view_proj, const Vec3& origin, const MeshBuffers& mesh, bool peel);
  // Layer `layer` of element e's cubes; returns their cull counts and the elements drawn in them.
  std::pair<CullCount, int> drawCubes(size_t e, int layer);
  // One face of layer `layer` of element e's cubes (within the scissor rectangle, if one is set): the
  // elements other cubes show, then the environment; adds to the cull counts and the elements drawn.
  void drawFace(size_t e, int layer, int face, CullCount& culled, int& drawn);
  // The static/dynamic split (issue 24): in layer `layer` of element e's cubes, only the texels that the moved
  // meshes cover now or covered when the cubes were drawn (`before`: their world boxes then) are drawn
  // again, each face within the scissor rectangle of those boxes, with the same draws as a whole face (so
  // they are the very texels a whole redraw makes; what the meshes do not cover shows nothing of them, the
  // environment's shading being local without shadows). Returns the faces drawn and adds their texels.
  int redrawWhereMoved(size_t e, int layer, const std::vector<size_t>& moved,
                       const std::vector<std::array<Vec3, 2>>& before, CullCount& culled, size_t& texels);
  // Element e in the second pass, from its mesh in element_slot[e]. Impostor with two layers (layer_draw): 0
  // the first draw, 2 the probe, 1 the second draw (drawElements).
  void drawElement(size_t e, int layer_draw, const PassCamera& eye);
  // The probe, and where some pixel needs them, the second layers' cubes and second draws; returns the note.
  std::string drawSecondLayers(const PassCamera& eye, const Framebuffer& target);

  // Cube-map reuse across frames. The cubes show the scene from each element's centre: they depend on the
  // environment, every element's pose (the centres, and the elements drawn in other cubes), the mode and
  // the map settings, never on the eye. What the cubes drawn last were drawn with:
  struct CubeKey {
    RenderMode mode = RenderMode::Envmap;
    int map_size = 0, layers = 1, follow = 0;
    size_t formats = 0;
    bool lens_in_cubes = false;
    ScenePoses poses;                              // the elements' poses and the meshes' motions
    std::vector<std::array<Vec3, 2>> mesh_boxes;   // per environment mesh, its world box (EnvironmentPass)
  };
  CubeKey keyNow(size_t formats) const;
  // What to do with the cubes drawn last: `full` says why they are to be drawn whole again ("" when not);
  // otherwise `moved` lists the animated meshes that moved since (drawn again where they are and were:
  // redrawWhereMoved; none: the cubes are reused as they are). Reuse needs a frame cache whose environment
  // has not changed (FrameCache::environment_changed) but by the animated meshes' motion
  // (FrameCache::only_meshes_moved), every element where it was, and no light casting shadows when a mesh
  // moved (its shadow on the static surfaces would move too).
  struct Staleness {
    std::string full;
    std::vector<size_t> moved;
  };
  Staleness staleness(const FrameCache* cache, const CubeKey& key) const;
  // Cube e's projection, with its near and far planes (cube_near, cube_far).
  Mat4 cubeProjection(size_t e) const;
  // Whether one of the moved meshes came within twice a cube's near plane of its centre.
  bool movedNearCube(const std::vector<size_t>& moved) const;

  RenderContext ctx;
  ImpostorMaps maps;
  std::optional<CubeKey> drawn_key;                 // the cubes' key; empty before the first draw
  bool layer1_drawn = false;  // the second layers' cubes were drawn with drawn_key's settings and elements,
  CubeKey layer1_key;         // and with these mesh motions and boxes (updated in place when they moved)
  int reused_frames = 0;                            // frames drawn from the cubes since they were drawn
  bool cubes_reused = false;                        // this frame's cubes are the last frame's
  std::vector<std::unique_ptr<CubeTarget>> cubes;   // one per element
  std::vector<std::unique_ptr<CubeTarget>> cubes1;  // impostor mode's second layers (impostorLayers), one per element
  // This frame's plan (prepare):
  RenderMode mode = RenderMode::Envmap;
  int layers = 1;               // ImpostorMaps::impostorLayers
  int follow = 0;               // ImpostorMaps::cubeElements: the elements the fragments follow through their cubes
  bool lens_in_cubes = false;   // ImpostorMaps::lensInCubes
  bool with_seen = false;       // the cubes hold seen points even in a colour-only frame (impostor mode)
  bool second_layers = false;   // the second layers are to be drawn where needed (layers > 1)
  std::vector<size_t> cube_mesh;     // per element drawn in other cubes: its mesh's pool index
  std::vector<size_t> element_slot;  // per element: its second-pass mesh's pool index
  // Per element: its cubes' near plane (cubeNearPlane, set when they are drawn) and far plane.
  std::vector<double> cube_near, cube_far;
  std::vector<ElementFrame> frames;  // this frame's elements with their quality (drawElements)
};

}  // namespace pvrr::gl

// Pvrr mode (the paper's two passes): the CPU stages (vertex rays, refraction, viewpoint fit, texture
// coordinates, with eye-fixed caching), the first-pass maps the plan (pvrr/method/pass_plan.h) asks for, rendered
// deepest first, and each element's draw with its maps, in the second pass or inside another element's map.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "pvrr/gl/mode_pass.h"
#include "pvrr/gl/stage_notes.h"
#include "pvrr/method/pass_plan.h"

namespace pvrr::gl {

class ImpostorMaps;

class PvrrPass : public ModePass {
 public:
  explicit PvrrPass(const RenderContext& c) : ctx(c) {}
  ~PvrrPass() override;
  PvrrPass(const PvrrPass&) = delete;
  PvrrPass& operator=(const PvrrPass&) = delete;

  void prepare(RenderMode mode, FrameStages& stages, FrameCache* cache) override;
  bool additiveDraws() const override;
  std::string drawElements(RenderMode mode, const PassCamera& eye, const Framebuffer& target) override;
  std::string finishedNote(const std::string& note) const override;
  std::vector<ElementFrame> takeElements() override { return std::move(frames); }

 private:
  // The CPU stages of the frame into `frames` and `opts`; returns whether nothing moved since the cached
  // frame (its first pass is then kept).
  bool cpuStages(FrameStages& stages, FrameCache* cache);
  void refineElement(size_t e);
  // The first pass and the nested passes, or why not (map reuse, the eye-fixed cache). skip_first_pass: nothing
  // moved since the cached frame; continuing: a cache that holds an earlier frame (maps are widened for reuse).
  void firstPass(FrameStages& stages, FrameCache* cache, bool skip_first_pass, bool continuing);
  VertexStageOptions optionsFor(size_t e) const;
  // Per map slot held: whether it is in R, G and B planes.
  std::vector<bool> planesSlots() const;
  Framebuffer& mapTarget(size_t i, int size, bool planes);
  // A vertex drawn from its traced colour in this patch: a totally reflected lens ray always; any other traced
  // ray only in a patch drawn traced (a neighbouring patch that shares the vertex draws it from its map).
  static bool usesTraced(const PatchView& pv, const VertexRay& r) {
    return r.traced && (r.status == VertexStatus::Tir || pv.draw_traced);
  }
  void uploadPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor, size_t set,
                   size_t seen_channel) const;
  void drawPvrrElement(const ElementFrame& f, size_t first_slot, const PassCamera& cam, int seen_channel);
  void drawDarkElement(const ElementFrame& f, const PassCamera& cam);
  int64_t closeUnreadTexels(const MapPass& mp, const std::array<int, 2>& region);
  CullCount renderPasses(size_t whole_slots, int64_t* skipped, int64_t* texels);
  // Per-fragment refinement (render.refine; pvrr/gl/pvrr_refine.cpp): which elements refine (refine_skip), their surface maps, the
  // fragment counters zeroed; and what the counters say once the frame's draws are done.
  // continuing: the frame continues an earlier frame's FrameCache (the quadratic split's parts wait for the view
  // to settle: RefineMidpoints::settled); else it stands alone and splits at once.
  void prepareRefinement(bool continuing);
  void setRefinement(const Program& p, const ElementFrame& f, size_t seen_channel) const;
  void unsetRefinement() const;
  void setRefinementView(const Program& p, int element, const PatchView& pv, const Framebuffer& map, int side) const;
  std::string refinementSkips(bool* any) const;
  // Whether this frame's second pass must count the refined elements' fragments (their draws then take the
  // counting variant, Programs::pvrr's count): true unless it draws exactly what the last counted frame drew
  // (nothing moved, the same maps, camera, target size, refined elements and split meshes), whose counts the
  // note then repeats. Records this frame's inputs.
  bool refineCountThisFrame(const PassCamera& eye, const Framebuffer& target);
  // A part of a patch's triangle (index into GridPatch::triangles): the triangle whose corners have the
  // barycentric coordinates b (of the patch triangle's corners 0, 1, 2); the whole triangle or one of its
  // subdivisions (uploadQuadraticPatch).
  struct RefineTri {
    uint32_t tri = 0;
    std::array<Vec3, 3> b{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  };
  // tris: the patch's triangles (or their parts) to upload; null: all of them, whole. A part's vertex data are
  // its triangle's, interpolated at its corners (all affine on the triangle, so its fragments see the same).
  void uploadRefinedPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor,
                          const std::vector<RefineTri>* tris = nullptr) const;
  // The quadratic split of a refined mirror's patch in the second pass (docs/method.md "Per-fragment
  // refinement"): the triangles whose exact rays at their edges' midpoints and centre (refineNodes) follow one
  // smooth surface of the map, and whose quadratic interpolant of those rays' coordinates meets the exact one at
  // the centre within kQuadraticTolRad, go to `quadratic` (uploaded as the REFINE_P2 program reads them). The
  // others are split in four (at their edges' midpoints, in the flat triangle) and their parts tested alike with
  // their own nodes (refineSubNode), `levels` deep; what still fails goes to *searched
  // (uploadRefinedPatch). Returns the number of quadratic triangles and parts; *counts: the patch's triangles.
  struct RefineSplitCounts {
    size_t whole_quadratic = 0, whole_searched = 0, split = 0;  // triangles drawn whole by each program, split
    double searched_area = 0;  // the split triangles' parts searched, in triangles (a part of level L: 4^-L)
  };
  size_t uploadQuadraticPatch(MeshBuffers& quadratic, std::vector<RefineTri>* searched, RefineSplitCounts* counts,
                              int levels, const ElementFrame& f, const PatchView& pv, const Vec3& anchor) const;
  // Draws patch view v of refined mirror f in the second pass, split: its quadratic triangles and parts by
  // `quadratic`, then the triangles with a searched part whole by `search` (in use on entry and on return, its
  // view's uniforms set), behind the quadratic parts: the depth test leaves it the searched parts' pixels. The split's meshes are
  // kept while the nodes are (refine_split): a frame in which nothing moved draws them as they are.
  void drawRefinedSplit(const Program& search, const Program& quadratic, const ElementFrame& f, size_t v,
                        const Vec3& anchor, const glm::vec3& seen_offset, const glm::vec2& st_scale,
                        const glm::vec2& st_max) const;
  // A node of the quadratic split: where the view ray from the element's eye through a point of the flat
  // triangle (an edge's midpoint, or the centre) meets the exact surface, reflected and traced into the scene.
  struct RefineNode {
    Vec3 hit{0};           // the exact hit, or the escaping ray's far point
    bool valid = false;    // the view ray met the exact surface within its parameter domain
    bool escaped = false;  // the reflected ray hit nothing
  };
  // The nodes of refined mirror f in this frame (edges by edgeKey, centres by triangleKey), computed once per
  // frame in which anything moved.
  const std::unordered_map<uint64_t, RefineNode>& refineNodes(const ElementFrame& f) const;
  // The node through the flat point at barycentric b of grid triangle (v0, v1, v2) of refined mirror f, for the
  // split's parts: computed once per frame in which anything moved (RefineMidpoints::sub_nodes).
  const RefineNode& refineSubNode(const ElementFrame& f, const uint32_t v[3], const Vec3& b) const;
  // The node through the flat point `flat` (the element's local frame), starting from the exact surface at
  // parameters uv (point p, derivatives du, dv).
  RefineNode traceRefineNode(const ElementFrame& f, Vec2 uv, Vec3 p, Vec3 du, Vec3 dv, const Vec3& flat) const;
  static uint64_t triangleKey(uint32_t i, uint32_t j, uint32_t k) {
    const uint32_t a = std::min({i, j, k}), c = std::max({i, j, k}), b = i ^ j ^ k ^ a ^ c;
    return 1ull << 63 | uint64_t(a) << 42 | uint64_t(b) << 21 | c;
  }
  // The exact surface point (local frame) at the parameter-domain midpoint of each edge of refined element f's
  // grid triangles, by edgeKey of its grid vertices; cached while its surface and grid stay the same.
  using EdgeMidpoints = std::unordered_map<uint64_t, Vec3>;
  static uint64_t edgeKey(uint32_t i, uint32_t j) { return uint64_t(std::min(i, j)) << 32 | std::max(i, j); }
  const EdgeMidpoints& edgeMidpoints(const ElementFrame& f) const;

  RenderContext ctx;
  std::vector<ElementFrame> frames;     // this frame's elements as seen from the eye
  std::vector<VertexStageOptions> opts;  // and their vertex-stage options
  PassPlan plan;                         // the last first pass's
  std::vector<std::unique_ptr<Framebuffer>> maps;  // first-pass maps, one per patch view (reused)
  std::vector<int> map_side;  // per map slot: the longer side its last first pass rendered (MapPass::side)
  // The serial of the first pass whose maps this renderer holds (FrameCache::maps_serial): unique in the
  // process (nextFirstPassSerial), so a cache filled by another renderer never matches.
  uint64_t first_pass_serial = 0;
  unsigned mask_vao = 0, mask_vbo = 0;  // closeUnreadTexels' quads
  std::vector<std::string> refine_skip;  // per element: why it is not refined, "" when it is
  unsigned refine_counters = 0;          // the second pass's failed, missed and (lenses) totally reflected
                                         // fragments (shaders/pvrr_refine.glsl)
  bool refine_lens = false;              // some refined element is a lens (its count in the note)
  unsigned refine_sampler = 0;           // linear filtering of the depth maps and the surface maps
  std::vector<unsigned> refine_queries;  // per element: its second-pass fragments (refined elements)
  std::unique_ptr<ImpostorMaps> surface_maps;  // the refined mirrors' surface maps (pvrr/impostor/surface_map.h)
                                               // and lenses' refractor height maps (lens_height_map.h)
  bool refine_counting = false;          // drawing the second pass (counted), not a nested pass
  bool refine_nothing_moved = false;     // this frame's CPU stages found nothing moved (prepare)
  bool refine_count_frame = false;       // this frame's second pass counts (refineCountThisFrame)
  std::vector<double> refine_count_key;  // the inputs of the last counted frame's refined draws
  mutable uint64_t refine_last_drawn = 0;       // and its counts: fragments drawn, and the counters'
  mutable std::array<unsigned, 3> refine_last_n{};
  mutable RefineSplitCounts refine_counts;  // this frame's second-pass mirror triangles (uploadQuadraticPatch)
  struct RefineMidpoints {
    cad::SurfacePtr surface;  // what they were computed for (held: never a reused address)
    std::vector<Vec2> params;
    EdgeMidpoints mids;
    // The quadratic split's starting points: the exact surface (local frame) at each edge's midpoint (edgeKey)
    // and each triangle's centre (triangleKey) in the parameter domain: parameters, point and derivatives.
    struct Start {
      Vec2 uv{0};
      Vec3 p{0}, du{0}, dv{0};
    };
    std::unordered_map<uint64_t, Start> starts;
    std::unordered_map<uint64_t, RefineNode> nodes;  // this frame's (refineNodes)
    bool nodes_fresh = false;
    // The nodes have lasted a frame: nothing moved since the frame that computed them. Only then, or in a
    // frame that stands alone (no earlier frame cached: refine_continuing false), are the failing triangles
    // split: their parts' nodes cost more than the triangles' own, so a moving frame searches them whole; as
    // the view settles they split once and stay split.
    bool settled = false;
    uint64_t generation = 0;  // the nodes' computation (refine_generation when they were computed)
    // The split's parts' nodes (refineSubNode), by the grid triangle's vertices in order and the point's
    // barycentric coordinates in 1/48ths; cleared with the nodes.
    std::map<std::pair<uint64_t, uint32_t>, RefineNode> sub_nodes;
  };
  mutable std::vector<RefineMidpoints> refine_mids;  // per element (edgeMidpoints)
  bool refine_continuing = false;  // this frame continues an earlier frame's FrameCache (prepareRefinement)
  mutable uint64_t refine_generation = 0;            // the last nodes computed (RefineMidpoints::generation)
  // A refined mirror's patch view in the second pass, split (drawRefinedSplit): its two meshes and triangle
  // counts, built from the nodes of `generation` (0: none yet). Released by the pass's destructor.
  struct RefineSplitMesh {
    uint64_t generation = 0;
    bool settled = false;  // built split (RefineMidpoints::settled)
    MeshBuffers quadratic, searched;
    size_t n_quadratic = 0, n_searched = 0;  // triangles and parts in each mesh
    RefineSplitCounts counts;
  };
  mutable std::vector<std::vector<RefineSplitMesh>> refine_split;  // per element, per patch view
};

}  // namespace pvrr::gl

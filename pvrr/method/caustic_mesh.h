// The raster caustics' CPU side (issue 23 item 2; pvrr/gl/caustic_pass.h draws them; docs/caustics.md
// "Raster caustics"). GL-free.
//
// Per light with caustics on (Light::caustics), per element and per wavelength sample, the reference's photons
// (pvrr/trace/light_tracer.h: the same aperture, the same exact transport, followPhoton) are traced at the
// vertices of a grid over the aperture instead of at jittered points: a "photon mesh". A cell whose four
// corners took the same path (all left the element, after as many specular events, towards the same receiver)
// is kept as two triangles; a cell whose corners differ (the element's rim, a shadow's edge, total internal
// reflection setting in) is traced again on a finer sub-grid and its consistent sub-cells kept; so is a cell on a
// curved receiver whose centre photon lands away from where its corners predict (the receiver shadowing itself).
// The GPU rasterizes the mesh into a caustic map over the aperture (one photon per texel, its exit ray and power
// interpolated between exact vertices) and splats the photons into the receivers' light maps.
//
// Receivers: the environment meshes that are planar (quads, grounds, flat meshes: every triangle in one
// plane), as the reference's receiver rectangles, and the curved meshes that are height fields over their
// best-fit plane (a bowl, a cylinder segment under 180 deg, a bumpy ground: heightFieldReceivers), whose maps lie
// in that plane and hold the irradiance per unit area of the surface (DepositOptions::height_field); each map
// covers a window about the caustic light landing on it (the square about the landed power's centroid holding
// kWindowQuantile of it, enlarged kWindowScale times), at most kMaxCausticReceivers receivers, by landed power.
// Meshes that are neither (closed solids: a box, a sphere; a cylinder over 180 deg) are split into sheets
// (pvrr/method/receiver_sheets.h), each a receiver of its own, planar or a height field over its own plane; a
// photon lands on the sheet its exact hit triangle belongs to. The notes say how many sheets, and name what is
// left out.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "pvrr/base/stats.h"
#include "pvrr/method/receiver_sheets.h"

#include "pvrr/scene/render_desc.h"
#include "pvrr/trace/irradiance_grid.h"
#include "pvrr/trace/light_tracer.h"

namespace pvrr {

inline constexpr int kMaxCausticReceivers = 4;

struct CausticPlanOptions {
  int grid = 64;      // aperture cells per side traced at their corners
  int refine = 8;     // sub-cells per side of a cell whose corners differ
  int cells = 256;    // light-map cells along a window's longer side
  int max_depth = 8;  // specular events before a photon is absorbed (the reference's default)
  DispersionMode dispersion = DispersionMode::Off;
  int spectral_samples = 16;
};

// One exact photon at a mesh vertex: where it left its element and how much power per unit aperture measure
// it carries (W/m^2 of aperture for a directional light, W per unit tangent-plane area for a point light,
// after the element's reflectance or Fresnel transmittances, a tinted lens's absorption along the photon's path
// inside the glass, exp(-alpha_c L) per channel (followPhoton, pvrr/trace/light_tracer.h), and the sample's
// colour weight).
struct CausticVertex {
  Vec2 xy{0};  // aperture coordinates
  Vec3 origin{0}, direction{0};
  Vec3 power_density{0};
  // Its exit ray's first environment hit: the distance along it (0 when none) and the triangle's unit normal.
  // The splat lands a photon on a curved receiver at the interpolation of its corners' exact distances.
  double t_hit = 0;
  Vec3 hit_normal{0};
  // The environment mesh its exit ray meets first (Scene::meshes index; -1: none). A kept cell's corners share it,
  // so the splat lands the cell's photons only on that mesh's light map: whatever stands between the element and
  // a receiver (an occluder that is not itself a mapped receiver) keeps the light off it.
  int mesh = -1;
  // The receiving surface it lands on: `mesh` for a mesh that is whole (planar, a height field, or none), else
  // the id of the sheet its hit triangle belongs to (CausticReceiver::surface; -1: no sheet). The splat compares
  // it with each receiver's.
  int surface = -1;
};

struct CausticMesh {
  int light = -1, element = -1, sample = 0;
  CausticAperture aperture;
  std::vector<CausticVertex> vertices;
  std::vector<uint32_t> triangles;  // three indices each
  Vec3 anchor{0};                   // world point the GPU's positions are relative to: the element's origin
  double lost_fraction = 0;         // aperture area of cells dropped for inconsistent corners, over the traced area
};

struct CausticReceiver {
  int mesh = -1;            // Scene::meshes index
  ReceiverRect full;        // the mesh's rectangle in its plane (cells unused); curved: its best-fit plane, through
                            // the middle of its heights
  ReceiverRect window;      // the light map: part of `full`, with its cells
  double landed_power = 0;  // scalar power of the vertex photons landing on it (the choice's measure)
  // A curved receiver (a height field over full's plane, not planar): its map holds the irradiance per unit area
  // of the surface (DepositOptions::height_field), and `height` the surface's height over the window's plane per
  // window cell (CausticReceiverMap::height; filled by planCaustics for the receivers it keeps).
  bool curved = false;
  std::vector<float> height;
  // A sheet of a mesh split into sheets (a box's face, a part of a sphere: sheetReceivers), or the whole mesh.
  ReceiverSheet sheet;
  int surface = -1;  // the id the photon-mesh vertices carry (CausticVertex::surface): `mesh` when whole
};

struct CausticPlan {
  std::vector<CausticMesh> meshes;
  std::vector<CausticReceiver> receivers;
  std::vector<std::string> notes;  // pairs skipped, receivers not mapped, with the reason
  long long traced = 0;            // exact photons traced at vertices
  double elapsed_ms = 0;
};

// The lights whose caustics are on (directional and point lights with Light::caustics).
std::vector<int> causticLights(const Scene& scene);
// The scene's planar environment meshes, as receiver rectangles (their bounding rectangle in their plane).
std::vector<CausticReceiver> planarReceivers(const Scene& scene);
// The scene's curved environment meshes that are height fields over their best-fit plane (the plane normal to
// the area-weighted mean of their triangles' normals, each triangle oriented by its vertex normals): every
// triangle faces that normal (cos above kMinHeightFieldCos) and no triangle's centroid lies over another
// triangle; curved = true, `full` their bounding rectangle in that plane through the middle of their heights.
// Planar meshes are planarReceivers', not these.
std::vector<CausticReceiver> heightFieldReceivers(const Scene& scene);
// The sheets of the scene's meshes that are neither planar nor height fields (splitIntoSheets): one receiver per
// sheet, planar (curved = false) or a height field over its own plane (curved = true), `full` its bounding
// rectangle there; `sheet` names its triangles. `unsplit` (if given) gets the names of the meshes with triangles
// in no sheet.
std::vector<CausticReceiver> sheetReceivers(const Scene& scene, std::vector<std::string>* unsplit = nullptr);
// The height of mesh `mesh` over `window`'s plane (along its normal, m) at each cell's centre (index j * cells_u
// + i): the triangles projected onto the plane, interpolated linearly; cells no triangle covers take the mean of
// their covered neighbours (two rings: the lookup's bilinear interpolation stays on the surface to its rim),
// else kNoHeight.
// `sheet` (not whole): only its triangles.
std::vector<float> receiverHeights(const EnvMesh& mesh, const ReceiverRect& window, const ReceiverSheet& sheet = {});
// Traces the photon meshes of every light with caustics on and chooses the receivers' windows.
// Throws pvrr::Error for options out of range.
CausticPlan planCaustics(const RayScene& rays, const CausticPlanOptions& options);

// The reference picture's caustic light (pvrr/trace/tracer.h TraceOptions::caustics): the light tracer's maps
// (photons_per_side^2 photons per light, element and sample) on the receiver windows and cells the raster
// plan chooses, so that both pictures add the same kind of map. `stages` gets the stage
// kReferenceCausticsStage: its photon count and receivers, or why it was skipped (no light with caustics on:
// then nullopt and the reference is what it was). Returns an empty field (lenses still block the caustic
// lights) when no caustic light lands on a planar or height-field receiver.
inline constexpr const char* kReferenceCausticsStage = "reference-caustics";
// The reference's photons per side: the light tracer's default, within 0.1 % of 1024^2 inside the burning
// lens's spot (docs/caustics.md "Convergence").
inline constexpr int kReferenceCausticPhotons = 512;
std::optional<CausticLightField> referenceCaustics(const RayScene& rays, const CausticPlanOptions& plan_options,
                                                   int photons_per_side, FrameStages& stages);

}  // namespace pvrr

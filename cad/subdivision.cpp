// Catmull-Clark limit surfaces of OBJ quad cages (OpenSubdiv 3.5, Bfr).
//
// Conventions:
// - The cage must be a regular grid of quads (every interior vertex of valence 4, boundary vertices of
//   valence 3, four corners of valence 2) forming a rectangle of nu x nv vertices, consistently wound. The
//   grid is recovered from the topology, not from the vertex order: its origin is the corner vertex with
//   the lowest OBJ index, u runs along the first edge of that corner's face (in the face's winding order)
//   and v along the other. du × dv therefore follows the faces' winding (right-hand rule), like an OBJ
//   normal.
// - Parameters (u, v) in [0, nu-1] x [0, nv-1]; grid face (a, b) covers [a, a+1] x [b, b+1] and is handed to
//   OpenSubdiv with vertices (a,b), (a+1,b), (a+1,b+1), (a,b+1), so Bfr's face parameterisation is
//   (u - a, v - b).
// - Boundaries: Sdc VTX_BOUNDARY_EDGE_AND_CORNER (boundary edges and corner vertices are interpolated).
// - Positions, first and second derivatives are evaluated exactly at the limit (Bfr::Surface::Evaluate with
//   second derivatives; every face of a regular grid is a regular bicubic patch).
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

using namespace OpenSubdiv;

struct ObjCage {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 4>> faces;  // 0-based vertex indices, OBJ order
};

int parseIndex(const std::string& token, int vertex_count, const std::string& where) {
  const std::string head = token.substr(0, token.find('/'));
  std::size_t used = 0;
  long idx = 0;
  try {
    idx = std::stol(head, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != head.size() || head.empty()) throw Error(where + ": bad vertex index \"" + token + "\"");
  if (idx < 0) idx += vertex_count + 1;  // OBJ relative index
  if (idx < 1 || idx > vertex_count)
    throw Error(where + ": vertex index " + head + " out of range (1.." + std::to_string(vertex_count) + ")");
  return int(idx - 1);
}

ObjCage parseObj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the OBJ cage");
  ObjCage cage;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    std::istringstream ls(line);
    std::string key;
    if (!(ls >> key) || key[0] == '#') continue;
    if (key == "v") {
      Vec3 p;
      if (!(ls >> p.x >> p.y >> p.z) || !isFinite(p)) throw Error(where + ": expected \"v x y z\"");
      cage.vertices.push_back(p);
    } else if (key == "f") {
      std::vector<int> f;
      std::string tok;
      while (ls >> tok) f.push_back(parseIndex(tok, int(cage.vertices.size()), where));
      if (f.size() != 4)
        throw Error(where + ": face with " + std::to_string(f.size()) +
                    " vertices; a Catmull-Clark cage here must be made of quads");
      cage.faces.push_back({f[0], f[1], f[2], f[3]});
    }
    // vt, vn, g, o, s, usemtl, mtllib, l: not used by a cage.
  }
  if (cage.faces.empty()) throw Error(path + ": no faces (expected a quad grid cage)");
  return cage;
}

struct Grid {
  int nu = 0, nv = 0;            // vertices per direction
  std::vector<int> vertex_at;    // grid (i, j) -> OBJ vertex, index i + nu * j
};

std::string cellName(int i, int j) { return "(" + std::to_string(i) + "," + std::to_string(j) + ")"; }

// Recovers the rectangular grid from the quads' adjacency (see the conventions above), or throws.
Grid findGrid(const ObjCage& cage, const std::string& path) {
  const int nvert = int(cage.vertices.size()), nface = int(cage.faces.size());
  // Directed edge -> face; a consistently wound manifold has each directed edge at most once.
  std::map<std::pair<int, int>, int> edge_face;
  std::vector<int> faces_at_vertex(std::size_t(nvert), 0);
  for (int f = 0; f < nface; ++f) {
    const auto& q = cage.faces[std::size_t(f)];
    for (int k = 0; k < 4; ++k) {
      const int a = q[std::size_t(k)], b = q[std::size_t((k + 1) % 4)];
      if (a == b) throw Error(path + ": face " + std::to_string(f + 1) + " repeats a vertex");
      if (!edge_face.emplace(std::make_pair(a, b), f).second)
        throw Error(path + ": edge " + std::to_string(a + 1) + "-" + std::to_string(b + 1) +
                    " is used twice in the same direction (inconsistent winding or a non-manifold cage)");
      ++faces_at_vertex[std::size_t(a)];
    }
  }
  for (int v = 0; v < nvert; ++v)
    if (faces_at_vertex[std::size_t(v)] == 0)
      throw Error(path + ": vertex " + std::to_string(v + 1) + " is used by no face");
  // The origin: the lowest-indexed vertex that lies in exactly one face (in a grid, a corner; anything
  // else fails the checks below). Its face's winding fixes the u and v directions.
  int origin = -1, origin_face = -1, origin_k = -1;
  for (int v = 0; v < nvert && origin < 0; ++v) {
    if (faces_at_vertex[std::size_t(v)] != 1) continue;
    for (int f = 0; f < nface && origin < 0; ++f)
      for (int k = 0; k < 4; ++k)
        if (cage.faces[std::size_t(f)][std::size_t(k)] == v) {
          origin = v;
          origin_face = f;
          origin_k = k;
          break;
        }
  }
  if (origin < 0) throw Error(path + ": the cage has no corner vertex (a vertex in only one face); not a quad grid");

  // Flood the faces across shared edges, assigning grid coordinates: in a face with its vertices at
  // c0, c1, c2, c3 (winding order) the grid steps are c1 - c0 and c3 - c0 (unit steps along u and v, in some
  // rotation); the neighbour across edge (c1, c2) continues them.
  std::vector<std::array<int, 2>> coord(std::size_t(nvert), {INT_MIN, INT_MIN});
  std::vector<bool> face_done(std::size_t(nface), false);
  auto assign = [&](int v, int i, int j) {
    auto& c = coord[std::size_t(v)];
    if (c[0] == INT_MIN) {
      c = {i, j};
    } else if (c[0] != i || c[1] != j) {
      throw Error(path + ": vertex " + std::to_string(v + 1) + " sits at two grid places " + cellName(c[0], c[1]) +
                  " and " + cellName(i, j) + " (extraordinary vertex or non-grid topology); a regular quad grid is required");
    }
  };
  {
    const auto& q = cage.faces[std::size_t(origin_face)];
    assign(q[std::size_t(origin_k)], 0, 0);
    assign(q[std::size_t((origin_k + 1) % 4)], 1, 0);
    assign(q[std::size_t((origin_k + 2) % 4)], 1, 1);
    assign(q[std::size_t((origin_k + 3) % 4)], 0, 1);
  }
  std::vector<int> stack{origin_face};
  face_done[std::size_t(origin_face)] = true;
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    const auto& q = cage.faces[std::size_t(f)];
    for (int k = 0; k < 4; ++k) {
      const int p = q[std::size_t(k)], r = q[std::size_t((k + 1) % 4)];  // edge p -> r
      const int p_prev = q[std::size_t((k + 3) % 4)], r_next = q[std::size_t((k + 2) % 4)];
      const auto it = edge_face.find({r, p});  // the neighbour traverses the edge the other way
      if (it == edge_face.end()) continue;
      const int g = it->second;
      const auto& w = cage.faces[std::size_t(g)];
      int m = 0;
      while (w[std::size_t(m)] != r) ++m;  // w: r, p, p', r'
      const int p_new = w[std::size_t((m + 2) % 4)], r_new = w[std::size_t((m + 3) % 4)];
      const auto cp = coord[std::size_t(p)], cr = coord[std::size_t(r)];
      const auto cpp = coord[std::size_t(p_prev)], crn = coord[std::size_t(r_next)];
      assign(p_new, 2 * cp[0] - cpp[0], 2 * cp[1] - cpp[1]);
      assign(r_new, 2 * cr[0] - crn[0], 2 * cr[1] - crn[1]);
      if (!face_done[std::size_t(g)]) {
        face_done[std::size_t(g)] = true;
        stack.push_back(g);
      }
    }
  }
  for (int f = 0; f < nface; ++f)
    if (!face_done[std::size_t(f)])
      throw Error(path + ": face " + std::to_string(f + 1) + " is not connected to the rest of the cage");

  int imin = INT_MAX, imax = INT_MIN, jmin = INT_MAX, jmax = INT_MIN;
  for (const auto& c : coord) {
    imin = std::min(imin, c[0]);
    imax = std::max(imax, c[0]);
    jmin = std::min(jmin, c[1]);
    jmax = std::max(jmax, c[1]);
  }
  Grid grid;
  grid.nu = imax - imin + 1;
  grid.nv = jmax - jmin + 1;
  const long expected_vertices = long(grid.nu) * grid.nv, expected_faces = long(grid.nu - 1) * (grid.nv - 1);
  if (imin != 0 || jmin != 0 || expected_vertices != nvert || expected_faces != nface)
    throw Error(path + ": the quads do not form a rectangular grid (" + std::to_string(nvert) + " vertices, " +
                std::to_string(nface) + " faces, spanning " + std::to_string(grid.nu) + " x " +
                std::to_string(grid.nv) + " grid places)");
  grid.vertex_at.assign(std::size_t(expected_vertices), -1);
  for (int v = 0; v < nvert; ++v) {
    int& slot = grid.vertex_at[std::size_t(coord[std::size_t(v)][0] + grid.nu * coord[std::size_t(v)][1])];
    if (slot >= 0)
      throw Error(path + ": vertices " + std::to_string(slot + 1) + " and " + std::to_string(v + 1) +
                  " share grid place " + cellName(coord[std::size_t(v)][0], coord[std::size_t(v)][1]));
    slot = v;
  }
  // Every face must be one unit cell, wound like the origin face.
  for (int f = 0; f < nface; ++f) {
    const auto& q = cage.faces[std::size_t(f)];
    std::array<int, 2> c[4];
    for (int k = 0; k < 4; ++k) c[k] = coord[std::size_t(q[std::size_t(k)])];
    int lo = 0;
    for (int k = 1; k < 4; ++k)
      if (c[k][0] + c[k][1] * 100000 < c[lo][0] + c[lo][1] * 100000) lo = k;
    const auto a = c[lo];
    const bool cell = c[(lo + 1) % 4] == std::array<int, 2>{a[0] + 1, a[1]} &&
                      c[(lo + 2) % 4] == std::array<int, 2>{a[0] + 1, a[1] + 1} &&
                      c[(lo + 3) % 4] == std::array<int, 2>{a[0], a[1] + 1};
    if (!cell)
      throw Error(path + ": face " + std::to_string(f + 1) + " is not a grid cell wound like the others");
  }
  return grid;
}

class SubdivisionSurface final : public Surface {
 public:
  SubdivisionSurface(const std::string& path, const ObjCage& cage, const Grid& grid) : path_(path), grid_(grid) {
    const int fu = grid.nu - 1, fv = grid.nv - 1;
    std::vector<int> verts_per_face(std::size_t(fu * fv), 4);
    std::vector<int> indices;
    indices.reserve(std::size_t(4 * fu * fv));
    for (int b = 0; b < fv; ++b)
      for (int a = 0; a < fu; ++a) {
        indices.push_back(grid.vertex_at[std::size_t(a + grid.nu * b)]);
        indices.push_back(grid.vertex_at[std::size_t(a + 1 + grid.nu * b)]);
        indices.push_back(grid.vertex_at[std::size_t(a + 1 + grid.nu * (b + 1))]);
        indices.push_back(grid.vertex_at[std::size_t(a + grid.nu * (b + 1))]);
      }
    Far::TopologyDescriptor desc;
    desc.numVertices = int(cage.vertices.size());
    desc.numFaces = fu * fv;
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = indices.data();
    Sdc::Options so;
    so.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    refiner_.reset(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, so)));
    if (!refiner_) throw Error(path + ": OpenSubdiv rejected the cage topology");
    Bfr::RefinerSurfaceFactory<> factory(*refiner_);

    std::vector<double> mesh_points;
    mesh_points.reserve(3 * cage.vertices.size());
    for (const Vec3& p : cage.vertices) {
      mesh_points.push_back(p.x);
      mesh_points.push_back(p.y);
      mesh_points.push_back(p.z);
    }
    faces_.resize(std::size_t(fu * fv));
    for (int f = 0; f < fu * fv; ++f) {
      FacePatch& fp = faces_[std::size_t(f)];
      if (!factory.InitVertexSurface(f, &fp.surface) || !fp.surface.IsValid())
        throw Error(path + ": OpenSubdiv found no limit surface for grid face " + std::to_string(f));
      fp.patch_points.resize(std::size_t(3 * fp.surface.GetNumPatchPoints()));
      fp.surface.PreparePatchPoints(mesh_points.data(), 3, fp.patch_points.data(), 3);
    }
  }

  ParamDomain domain() const override { return {0, double(grid_.nu - 1), 0, double(grid_.nv - 1)}; }

  SurfaceDerivs evaluate(double u, double v) const override {
    const int fu = grid_.nu - 1, fv = grid_.nv - 1;
    // Points on a face boundary belong to the lower face; outside the domain the end face's polynomial
    // continues (no clamping), which keeps evaluation smooth for callers that step a hair outside.
    const int a = std::clamp(int(std::floor(u)), 0, fu - 1), b = std::clamp(int(std::floor(v)), 0, fv - 1);
    const FacePatch& fp = faces_[std::size_t(a + fu * b)];
    const double uv[2] = {u - a, v - b};
    double P[3], Du[3], Dv[3], Duu[3], Duv[3], Dvv[3];
    fp.surface.Evaluate(uv, fp.patch_points.data(), 3, P, Du, Dv, Duu, Duv, Dvv);
    auto vec = [](const double* x) { return Vec3(x[0], x[1], x[2]); };
    return {vec(P), vec(Du), vec(Dv), vec(Duu), vec(Duv), vec(Dvv)};
  }

  std::string describe() const override {
    return "Catmull-Clark limit surface, " + std::to_string(grid_.nu) + "x" + std::to_string(grid_.nv) +
           " vertex cage (" + path_ + ")";
  }

 private:
  struct FacePatch {
    Bfr::Surface<double> surface;
    std::vector<double> patch_points;  // xyz
  };
  std::string path_;
  Grid grid_;
  std::unique_ptr<Far::TopologyRefiner> refiner_;
  std::vector<FacePatch> faces_;
};

}  // namespace

std::shared_ptr<const Surface> loadSubdivisionCage(const std::string& obj_path) {
  const ObjCage cage = parseObj(obj_path);
  const Grid grid = findGrid(cage, obj_path);
  return std::make_shared<SubdivisionSurface>(obj_path, cage, grid);
}

}  // namespace pvrr::cad

#include "pvrr/gl/ao_vertex_receivers.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/stage_notes.h"

namespace pvrr::gl {

namespace {
// One vertex in the layout of the grids' and the merged buffers (AoVertexReceivers::kAoStride floats): position,
// normal, texture coordinates, the occlusion for the normal and for its opposite.
void appendVertex(std::vector<float>& data, const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv, float o, float o_back) {
  data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, o, o_back});
}
}  // namespace

AoVertexReceivers::~AoVertexReceivers() {
  for (auto& [k, e] : entries_) e.buffers.release();
  for (auto& [k, e] : merged_) e.buffers.release();
}

std::vector<Mat4> AoVertexReceivers::key(size_t m) const {
  std::vector<Mat4> k = {scene_.meshMotion(m)};
  for (const AoField& f : fields_) k.push_back(occluderMotion(scene_, f.occluder));
  return k;
}

const MeshBuffers* AoVertexReceivers::grid(size_t m, size_t g, const std::vector<uint32_t>& triangles, const Vec3& normal) {
  Entry& e = entries_[{m, g}];
  std::vector<Mat4> now = key(m);
  if (e.key == now) return e.why.empty() ? &e.buffers : nullptr;
  e.key = std::move(now);
  const auto t0 = Clock::now();
  const EnvMesh& mesh = scene_.meshes[m];
  const std::optional<AoRectangle> r = aoRectangleOf(mesh, triangles, normal, e.why);
  if (!r) return nullptr;
  e.why.clear();
  const AoReceiverGrid grid = buildAoReceiverGrid(*r, mesh.anchor, mesh.occluder, fields_, scene_);
  // As EnvironmentPass uploads a mesh (position, normal, texture coordinates), and the two occlusions.
  std::vector<float>& data = e.data;
  data.clear();
  data.reserve(grid.positions.size() * kAoStride);
  const glm::vec3 n(normal);
  for (size_t i = 0; i < grid.positions.size(); ++i)
    appendVertex(data, glm::vec3(grid.positions[i]), n, glm::vec2(grid.uvs[i]), grid.occlusion[i][0], grid.occlusion[i][1]);
  e.indices = grid.indices;
  uploadMesh(e.buffers, data, {3, 3, 2, 2}, grid.indices);
  checkGlError("uploading an ambient occlusion grid");
  e.vertices = int(grid.positions.size());
  e.triangles = int(grid.indices.size() / 3);
  last_build_ms_ = msSince(t0);
  build_ms_ += last_build_ms_;
  ++builds_;
  return &e.buffers;
}

const std::vector<float>* AoVertexReceivers::gridData(size_t m, size_t g) const {
  const auto it = entries_.find({m, g});
  return it == entries_.end() || !it->second.why.empty() ? nullptr : &it->second.data;
}

const std::vector<uint32_t>* AoVertexReceivers::gridIndices(size_t m, size_t g) const {
  const auto it = entries_.find({m, g});
  return it == entries_.end() || !it->second.why.empty() ? nullptr : &it->second.indices;
}

const AoVertexReceivers::Merged* AoVertexReceivers::merged(size_t m, const std::vector<Face>& faces) {
  uint32_t mask = 0;
  for (size_t g = 0; g < faces.size(); ++g) mask |= faces[g].grid ? 1u << g : 0u;
  Merged& e = merged_[{m, mask}];
  std::vector<Mat4> now = key(m);
  if (e.key == now) return &e;
  const auto t0 = Clock::now();
  // Every grid current first (each made again where something moved).
  for (size_t g = 0; g < faces.size(); ++g)
    if (faces[g].grid && !grid(m, g, *faces[g].triangles, faces[g].normal)) return nullptr;
  e.key = std::move(now);
  e.data.clear();
  e.indices.clear();
  e.grids = 0;
  const EnvMesh& mesh = scene_.meshes[m];
  if (mask + 1 != 1u << faces.size()) {  // some face drawn as it is: the mesh's vertices, without occlusion
    e.data.reserve(mesh.positions.size() * kAoStride);
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      appendVertex(e.data, mesh.positions[i], mesh.normals[i], mesh.uvs[i], 0.0f, 0.0f);
  }
  // Face after face, each triangle into the plain part or the occluded one.
  std::vector<uint32_t> plain, occluded;
  std::vector<int> plain_face, plain_source, occluded_face, occluded_source;
  auto add = [&](uint32_t a, uint32_t b, uint32_t c, int g, int source) {
    float most = 0;
    for (const uint32_t v : {a, b, c}) most = std::max({most, e.data[size_t(v) * kAoStride + 8], e.data[size_t(v) * kAoStride + 9]});
    const bool is_plain = most < kAoValueNegligible;
    (is_plain ? plain : occluded).insert((is_plain ? plain : occluded).end(), {a, b, c});
    (is_plain ? plain_face : occluded_face).push_back(g);
    (is_plain ? plain_source : occluded_source).push_back(source);
  };
  for (size_t g = 0; g < faces.size(); ++g) {
    if (!faces[g].grid) {
      int source = 0;
      for (const uint32_t t : *faces[g].triangles) {
        const auto& tri = mesh.triangles[t];
        add(tri.x, tri.y, tri.z, int(g), source++);
      }
      continue;
    }
    const Entry& grid_entry = entries_.at({m, g});
    const uint32_t base = uint32_t(e.data.size() / kAoStride);
    e.data.insert(e.data.end(), grid_entry.data.begin(), grid_entry.data.end());
    const std::vector<uint32_t>& gi = grid_entry.indices;
    for (size_t t = 0; t + 2 < gi.size(); t += 3) add(base + gi[t], base + gi[t + 1], base + gi[t + 2], int(g), int(t / 3));
    ++e.grids;
  }
  e.plain = int(plain.size());
  e.indices = std::move(plain);
  e.indices.insert(e.indices.end(), occluded.begin(), occluded.end());
  e.face = std::move(plain_face);
  e.face.insert(e.face.end(), occluded_face.begin(), occluded_face.end());
  e.source = std::move(plain_source);
  e.source.insert(e.source.end(), occluded_source.begin(), occluded_source.end());
  uploadMesh(e.buffers, e.data, {3, 3, 2, 2}, e.indices);
  checkGlError("uploading a mesh's ambient occlusion grids");
  ++merges_;
  build_ms_ += msSince(t0);
  return &e;
}

void AoVertexReceivers::fallback(size_t m, const std::string& why) { fallbacks_[m] = why; }

std::string AoVertexReceivers::note() const {
  int faces = 0, vertices = 0, triangles = 0;
  std::map<size_t, std::string> without = fallbacks_;
  for (const auto& [k, e] : entries_) {
    if (!e.why.empty()) {
      without[k.first] = e.why;
      continue;
    }
    ++faces;
    vertices += e.vertices;
    triangles += e.triangles;
  }
  char text[256];
  std::snprintf(text, sizeof text,
                "vertex values (faces drawn so far) on %d face%s: %d triangles, %d vertices, %d grid%s made in %.1f ms (the last %.1f ms; "
                "made again only when the mesh or an occluder moves)",
                faces, faces == 1 ? "" : "s", triangles, vertices, builds_, builds_ == 1 ? "" : "s", build_ms_,
                last_build_ms_);
  std::string out = text;
  std::set<size_t> one_draw;
  size_t merged_triangles = 0, plain_triangles = 0;
  for (const auto& [k, e] : merged_) {
    one_draw.insert(k.first);
    merged_triangles += e.face.size();
    plain_triangles += size_t(e.plain / 3);
  }
  std::snprintf(text, sizeof text,
                "; %zu mesh%s drawn as one buffer holding its faces' grids (%d buffer%s made, %zu triangles, %zu of them "
                "drawn without the values: below %.1f/255)",
                one_draw.size(), one_draw.size() == 1 ? "" : "es", merges_, merges_ == 1 ? "" : "s", merged_triangles,
                plain_triangles, kAoValueNegligible * 255);
  out += text;
  if (!without.empty()) {
    out += "; per fragment (occlusion image or fields):";
    for (const auto& [m, why] : without) out += " " + scene_.meshes[m].name + " (" + why + ")";
  }
  return out;
}

}  // namespace pvrr::gl

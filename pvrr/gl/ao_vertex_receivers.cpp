#include "pvrr/gl/ao_vertex_receivers.h"

#include <cstdio>
#include <set>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/stage_notes.h"

namespace pvrr::gl {

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
  for (size_t i = 0; i < grid.positions.size(); ++i) {
    const glm::vec3 p(grid.positions[i]);
    const glm::vec2 uv(grid.uvs[i]);
    data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, grid.occlusion[i][0], grid.occlusion[i][1]});
  }
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
  e.face.clear();
  e.grids = 0;
  const EnvMesh& mesh = scene_.meshes[m];
  if (mask + 1 != 1u << faces.size()) {  // some face drawn as it is: the mesh's vertices, without occlusion
    e.data.reserve(mesh.positions.size() * kAoStride);
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const glm::vec3 pos = mesh.positions[i], n = mesh.normals[i];
      const glm::vec2 uv = mesh.uvs[i];
      e.data.insert(e.data.end(), {pos.x, pos.y, pos.z, n.x, n.y, n.z, uv.x, uv.y, 0.0f, 0.0f});
    }
  }
  for (size_t g = 0; g < faces.size(); ++g) {
    if (!faces[g].grid) {
      for (const uint32_t t : *faces[g].triangles) {
        const auto& tri = mesh.triangles[t];
        e.indices.insert(e.indices.end(), {tri.x, tri.y, tri.z});
        e.face.push_back(int(g));
      }
      continue;
    }
    const Entry& grid_entry = entries_.at({m, g});
    const uint32_t base = uint32_t(e.data.size() / kAoStride);
    e.data.insert(e.data.end(), grid_entry.data.begin(), grid_entry.data.end());
    for (const uint32_t i : grid_entry.indices) e.indices.push_back(base + i);
    e.face.insert(e.face.end(), grid_entry.indices.size() / 3, int(g));
    ++e.grids;
  }
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
  for (const auto& [k, e] : merged_) one_draw.insert(k.first);
  std::snprintf(text, sizeof text, "; %zu mesh%s drawn as one draw holding its faces' grids (%d buffer%s made)",
                one_draw.size(), one_draw.size() == 1 ? "" : "es", merges_, merges_ == 1 ? "" : "s");
  out += text;
  if (!without.empty()) {
    out += "; per fragment (occlusion image or fields):";
    for (const auto& [m, why] : without) out += " " + scene_.meshes[m].name + " (" + why + ")";
  }
  return out;
}

}  // namespace pvrr::gl

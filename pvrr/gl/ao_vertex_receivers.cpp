#include "pvrr/gl/ao_vertex_receivers.h"

#include <cstdio>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/stage_notes.h"

namespace pvrr::gl {

AoVertexReceivers::~AoVertexReceivers() {
  for (auto& [k, e] : entries_) e.buffers.release();
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
  std::vector<float> data;
  data.reserve(grid.positions.size() * 10);
  const glm::vec3 n(normal);
  for (size_t i = 0; i < grid.positions.size(); ++i) {
    const glm::vec3 p(grid.positions[i]);
    const glm::vec2 uv(grid.uvs[i]);
    data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, grid.occlusion[i][0], grid.occlusion[i][1]});
  }
  uploadMesh(e.buffers, data, {3, 3, 2, 2}, grid.indices);
  checkGlError("uploading an ambient occlusion grid");
  e.vertices = int(grid.positions.size());
  e.triangles = int(grid.indices.size() / 3);
  last_build_ms_ = msSince(t0);
  build_ms_ += last_build_ms_;
  ++builds_;
  return &e.buffers;
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
  if (!without.empty()) {
    out += "; per fragment (occlusion image or fields):";
    for (const auto& [m, why] : without) out += " " + scene_.meshes[m].name + " (" + why + ")";
  }
  return out;
}

}  // namespace pvrr::gl

#include "pvrr/gl/element_mesh.h"

namespace pvrr::gl {

MeshPool::~MeshPool() {
  for (auto& m : meshes_) m.release();
}

MeshBuffers& MeshPool::slot() {
  if (meshes_.size() <= next_) meshes_.resize(next_ + 1);
  return meshes_[next_++];
}

void uploadElementGrid(MeshBuffers& mb, const Scene& scene, const ElementFrame& f, const Vec3& anchor) {
  std::vector<float> data;
  data.reserve(f.world_pos.size() * kElementFloats);
  const bool has_rays = !f.rays.empty();
  const cad::ParamDomain domain = scene.elements[size_t(f.element)].frontSurface().domain();
  for (size_t i = 0; i < f.world_pos.size(); ++i) {
    glm::vec3 p(f.world_pos[i] - anchor), n(f.world_normal[i]);
    const glm::vec3 d = has_rays ? glm::vec3(f.rays[0][i].dir) : glm::vec3(0, 0, 1);
    const glm::vec3 tr = has_rays ? glm::vec3(f.rays[0][i].transmittance) : glm::vec3(1);
    // The surface parameters normalised to the domain in double (pvrr/impostor/surface_map.h).
    const glm::vec2 uv = i < f.grid.params.size()
                             ? glm::vec2((f.grid.params[i].x - domain.u0) / (domain.u1 - domain.u0),
                                         (f.grid.params[i].y - domain.v0) / (domain.v1 - domain.v0))
                             : glm::vec2(0.5f);
    data.insert(data.end(), {p.x, p.y, p.z, n.x, n.y, n.z, d.x, d.y, d.z, uv.x, uv.y, 1, 0, 0, 1, tr.x, tr.y, tr.z,
                             0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0});
  }
  std::vector<uint32_t> idx;
  for (const auto& t : f.grid.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
  uploadMesh(mb, data, kElementLayout, idx);
}

void setElementMaterial(const Program& p, const Element& el, int index) {
  p.set("u_element_id", float(index + 1));
  p.set("u_metal", el.mirror.metal ? 1 : 0);
  p.set("u_reflectance", glm::vec3(el.mirror.reflectance));
  p.set("u_metal_n", glm::vec3(el.mirror.n));
  p.set("u_metal_k", glm::vec3(el.mirror.k));
}

}  // namespace pvrr::gl

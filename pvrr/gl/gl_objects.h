// The GL objects the render passes share, in one place: cube-map targets, element and environment mesh
// buffers, data textures, and the camera-relative matrices they are drawn with. Internal to pvrr/gl; GL names
// are plain unsigned ints here (GLuint, GLenum), so that no GL header is included.
#pragma once
#include <initializer_list>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/base/math.h"
#include "pvrr/gl/program.h"

namespace pvrr::gl {

inline glm::mat4 toFloat(const Mat4& m) { return glm::mat4(m); }

// The projection * view of a camera whose origin is `origin`, acting on points relative to that origin.
// The view's translation is folded in double precision, so nothing large reaches float.
inline Mat4 relativeViewProj(const Mat4& proj, const Mat4& view, const Vec3& origin) {
  return proj * view * glm::translate(Mat4(1.0), origin);
}

// Cube-map render target for the envmap baseline (Framebuffer covers the 2D targets): N colour cube maps
// and a depth buffer; selectFace() attaches one face of each.
struct CubeTarget {
  unsigned fbo = 0, depth = 0;
  std::vector<unsigned> colors;
  int size = 0;
  CubeTarget() = default;
  CubeTarget(const CubeTarget&) = delete;
  CubeTarget& operator=(const CubeTarget&) = delete;
  ~CubeTarget() { release(); }
  void release();
  // n x n faces; `formats`: each colour cube map's GL internal format (GL_RGBA16F, GL_RGBA32F).
  void create(int n, const std::vector<unsigned>& formats);
  // Binds the target with `face` attached, sets the viewport and clears it.
  void selectFace(int face) const;
};

struct MeshBuffers {
  unsigned vao = 0, vbo = 0, ebo = 0;
  int count = 0;
  void release();
};

// Interleaved float attributes: `layout` lists each attribute's component count, in location order.
void uploadMesh(MeshBuffers& mb, const std::vector<float>& data, const std::vector<int>& layout,
                const std::vector<uint32_t>& indices);
void draw(const MeshBuffers& mb);

// A 2D float texture of w x h texels, 1 or 4 floats each, made or replaced in `tex`. The impostor shader
// reads these maps with texelFetch and filters them in float itself (shaders/bilinear.glsl):
// nearest, clamped.
void uploadDataTexture(unsigned& tex, int internal_format, int w, int h, int channels, const float* data);

// Binds `textures` to units first, first + 1, ... and names them in `p`; unit 0 active after.
void bindDataTextures(const Program& p, int first, std::initializer_list<std::pair<const char*, unsigned>> textures);

}  // namespace pvrr::gl

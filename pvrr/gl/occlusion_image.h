// A pass's low-resolution occlusion image (issue 24, docs/performance.md "Ambient occlusion"): the static
// receivers' ambient occlusion, evaluated into an R8 image kFactor times smaller per axis than the pass's
// viewport (with a depth buffer of its own), then read by the pass's fragments with one bilinear lookup
// (shaders/ambient_occlusion.glsl, AO_SCREEN) whatever the number of occluders. EnvironmentPass draws into it.
#pragma once
#include <glm/vec4.hpp>

namespace pvrr::gl {

class OcclusionImage {
 public:
  static constexpr int kFactor = 8;

  OcclusionImage() = default;
  ~OcclusionImage();
  OcclusionImage(const OcclusionImage&) = delete;
  OcclusionImage& operator=(const OcclusionImage&) = delete;

  // Makes the image the draw target for the bound viewport (remade when its size changes), cleared to no
  // occlusion and depth 1, scissor and blending off; remembers the target and state it replaces.
  void begin();
  // Restores what begin() replaced and binds the image on texture unit `unit` for the pass's draws.
  void end(int unit);
  // Maps a window pixel of the viewport at begin() to the image's coordinates: (1/w, 1/h, -x0/w, -y0/h).
  glm::vec4 coordinates() const;

 private:
  unsigned fbo_ = 0, image_ = 0, depth_ = 0;
  int size_[2] = {0, 0};
  int viewport_[4] = {0, 0, 1, 1};
  int target_ = 0;
  bool scissor_ = false, blend_ = false;
};

}  // namespace pvrr::gl

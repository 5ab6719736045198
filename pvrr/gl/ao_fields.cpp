#include "pvrr/gl/ao_fields.h"

#include <cstdio>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/stage_notes.h"
#include "pvrr/trace/ambient_occlusion.h"

namespace pvrr::gl {

namespace {

bool anyAmbientLight(const Scene& scene) {
  for (const Light& l : scene.lights)
    if (l.type == Light::Type::Ambient) return true;
  return false;
}

}  // namespace

std::string ambientOcclusionSkipReason(const Scene& scene) {
  if (!scene.render.ambient_occlusion.on) return "off (render.ambient_occlusion)";
  if (occluderCount(scene) == 0) return "no environment object has \"ambient_occlusion\"";
  if (!anyAmbientLight(scene)) return "the scene has no ambient light to occlude";
  return "";
}

std::vector<std::string> aoDefines(const Scene& scene) {
  if (!ambientOcclusionSkipReason(scene).empty()) return {};
  const AmbientOcclusionDesc& a = scene.render.ambient_occlusion;
  int side = 1;
  while (side * side < a.samples) ++side;
  return {"#define AMBIENT_OCCLUSION", "#define AO_FIELDS " + std::to_string(occluderCount(scene)),
          "#define AO_POSITIONS " + std::to_string(a.positions),
          "#define AO_DIRECTIONS " + std::to_string(a.directions), "#define AO_SIDE " + std::to_string(side)};
}

AoFields::AoFields(const Scene& scene, int max_texture_units) : scene_(scene), unit_(max_texture_units - 4) {
  if (!ambientOcclusionSkipReason(scene).empty()) return;
  const auto t0 = Clock::now();
  fields_ = buildAoFields(scene);
  build_ms_ = msSince(t0);
  if (fields_.empty()) return;
  const int w = fields_[0].width();
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_2D_ARRAY, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R8, w, w, GLsizei(fields_.size()), 0, GL_RED, GL_UNSIGNED_BYTE, nullptr);
  for (size_t i = 0; i < fields_.size(); ++i)
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, GLint(i), w, w, 1, GL_RED, GL_UNSIGNED_BYTE, fields_[i].data.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  checkGlError("uploading the ambient occlusion fields");
}

AoFields::~AoFields() {
  if (texture_) glDeleteTextures(1, &texture_);
}

void AoFields::bind(const Program& p, const Vec3& origin) const {
  if (!active()) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + unit_));
  glBindTexture(GL_TEXTURE_2D_ARRAY, texture_);
  glActiveTexture(GL_TEXTURE0);
  p.set("u_ao_field", unit_);
  for (size_t i = 0; i < fields_.size(); ++i) {
    const AoField& f = fields_[i];
    const Mat4 motion = occluderMotion(scene_, f.occluder);
    const std::string k = "[" + std::to_string(i) + "]";
    // The field's centre where its object is now, relative to the pass's origin (in double), and the
    // rotation from the field's frame to the world.
    p.set("u_ao_centre" + k, glm::vec3(Vec3(motion * Vec4(f.centre, 1.0)) - origin));
    p.set("u_ao_rotation" + k, glm::mat3(Mat3(motion)));
    p.set("u_ao_radius" + k, float(f.radius));
  }
  p.set("u_ao_self", -1);
}

void AoFields::setReceiver(const Program& p, int occluder) const {
  if (active()) p.set("u_ao_self", occluder);
}

void AoFields::note(FrameStages& stages) const {
  const std::string reason = ambientOcclusionSkipReason(scene_);
  if (!reason.empty()) {
    stages.skipped(kAmbientOcclusionStage, reason);
    return;
  }
  size_t bytes = 0;
  for (const AoField& f : fields_) bytes += f.bytes();
  const AmbientOcclusionDesc& a = scene_.render.ambient_occlusion;
  char text[256];
  std::snprintf(text, sizeof text, "%s %zu field%s, %d^2 positions x %d^2 directions, %.1f MB (8 bit), built in %.0f ms",
                noted_ ? "reused" : "built", fields_.size(), fields_.size() == 1 ? "" : "s", a.positions, a.directions,
                double(bytes) / (1 << 20), build_ms_);
  stages.ran(kAmbientOcclusionStage, noted_ ? 0 : build_ms_, int(fields_.size()), text);
  noted_ = true;
}

}  // namespace pvrr::gl

#include "pvrr/gl/ao_fields.h"

#include <cstdio>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/texture_units.h"
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
  return {"#define AMBIENT_OCCLUSION", "#define AO_FIELDS " + std::to_string(occluderCount(scene)),
          "#define AO_VOLUME " + std::to_string(kAoVolumeSize)};
}

AoFields::AoFields(const Scene& scene, int max_texture_units) : scene_(scene), unit_(units::aoVolume(max_texture_units)) {
  if (!ambientOcclusionSkipReason(scene).empty()) return;
  const auto t0 = Clock::now();
  fields_ = buildAoFields(scene);
  build_ms_ = msSince(t0);
  if (fields_.empty()) return;
  // One RGBA8 3D texture: per field two blocks of n slices (O for +x, -x, +y, -y; then +z, -z), filtered
  // linearly, clamped at the edges (the shader keeps z inside its block).
  const size_t n = kAoVolumeSize, slice = n * n;
  std::vector<uint8_t> texels(slice * n * 2 * fields_.size() * 4, 0);
  for (size_t f = 0; f < fields_.size(); ++f)
    for (size_t point = 0; point < slice * n && !fields_[f].volume.empty(); ++point)
      for (size_t half = 0; half < 2; ++half)
        for (size_t c = 0; c < 4; ++c)
          texels[(((2 * f + half) * n * slice) + point) * 4 + c] = fields_[f].volume[point * 8 + half * 4 + c];
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_3D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, GLsizei(n), GLsizei(n), GLsizei(2 * n * fields_.size()), 0, GL_RGBA,
               GL_UNSIGNED_BYTE, texels.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAX_LEVEL, 0);
  glBindTexture(GL_TEXTURE_3D, 0);
  volume_bytes_ = texels.size();
  checkGlError("uploading the ambient occlusion fields");
}

AoFields::~AoFields() {
  if (texture_) glDeleteTextures(1, &texture_);
}

void AoFields::bind(const Program& p, const Vec3& origin) const {
  if (!active()) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + unit_));
  glBindTexture(GL_TEXTURE_3D, texture_);
  glActiveTexture(GL_TEXTURE0);
  p.set("u_ao_volume", unit_);
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
  std::snprintf(text, sizeof text,
                "%s %zu field%s, %d^2 positions x %d^2 directions, %.1f MB (8 bit); occlusion volumes %d^3, %.1f MB; "
                "built in %.0f ms",
                noted_ ? "reused" : "built", fields_.size(), fields_.size() == 1 ? "" : "s", a.positions, a.directions,
                double(bytes) / (1 << 20), kAoVolumeSize, double(volume_bytes_) / (1 << 20), build_ms_);
  stages.ran(kAmbientOcclusionStage, noted_ ? 0 : build_ms_, int(fields_.size()), text);
  noted_ = true;
}

}  // namespace pvrr::gl

#include "pvrr/gl/ao_fields.h"

#include <algorithm>
#include <cmath>
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

// At most this many occluders are transformed per vertex (AO_PER_VERTEX, shaders/ambient_occlusion.glsl).
constexpr int kAoPerVertexFields = 7;
// At most this many heights of horizontal planes get ground maps (the others read the volumes).
constexpr size_t kMaxGroundHeights = 8;
// Two heights closer than this (m) are one; a plane's vertices and normals are this level and vertical.
constexpr double kLevelTolerance = 1e-6;

// The heights of the static horizontal planes that are no occluder's (the ground maps'), and per mesh the
// index of its height (-1: not such a plane).
struct Planes {
  std::vector<double> heights;
  std::vector<int> mesh_height;
};
Planes horizontalPlanes(const Scene& scene) {
  Planes out;
  out.mesh_height.assign(scene.meshes.size(), -1);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvMesh& mesh = scene.meshes[m];
    if (mesh.occluder >= 0 || scene.meshAnimated(m) || mesh.positions.empty()) continue;
    const double y0 = mesh.anchor.y + double(mesh.positions[0].y);
    const bool level = std::all_of(mesh.positions.begin(), mesh.positions.end(), [&](const glm::vec3& p) {
      return std::abs(mesh.anchor.y + double(p.y) - y0) < kLevelTolerance;
    });
    const bool vertical = std::all_of(mesh.normals.begin(), mesh.normals.end(),
                                      [](const glm::vec3& n) { return std::abs(std::abs(double(n.y)) - 1) < kLevelTolerance; });
    if (!level || !vertical || mesh.normals.empty()) continue;
    size_t h = 0;
    while (h < out.heights.size() && std::abs(out.heights[h] - y0) >= kLevelTolerance) ++h;
    if (h == out.heights.size()) {
      if (h == kMaxGroundHeights) continue;
      out.heights.push_back(y0);
    }
    out.mesh_height[m] = int(h);
  }
  return out;
}

}  // namespace

void linearClampedOneLevel(unsigned target) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (target == GL_TEXTURE_3D) glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
}

std::string ambientOcclusionSkipReason(const Scene& scene) {
  if (!scene.render.ambient_occlusion.on) return "off (render.ambient_occlusion)";
  if (occluderCount(scene) == 0) return "no environment object has \"ambient_occlusion\"";
  if (!anyAmbientLight(scene)) return "the scene has no ambient light to occlude";
  return "";
}

std::vector<std::string> aoDefines(const Scene& scene, AoReceiver receiver) {
  if (receiver == AoReceiver::None || !ambientOcclusionSkipReason(scene).empty()) return {};
  if (receiver == AoReceiver::Screen) return {"#define AMBIENT_OCCLUSION", "#define AO_SCREEN"};
  if (receiver == AoReceiver::Vertex) return {"#define AMBIENT_OCCLUSION", "#define AO_VALUES"};
  std::vector<std::string> d = {"#define AMBIENT_OCCLUSION", "#define AO_FIELDS " + std::to_string(occluderCount(scene)),
                                "#define AO_VOLUME " + std::to_string(kAoVolumeSize)};
  // 6 varying components per occluder (offset and face normal): with the environment's own 14, within the 64
  // vertex outputs GL 4.x guarantees up to kAoPerVertexFields occluders; more are transformed per fragment.
  if (occluderCount(scene) <= kAoPerVertexFields) d.push_back("#define AO_PER_VERTEX");
  if (receiver == AoReceiver::Ground) {
    d.push_back("#define AO_GROUND");
    d.push_back("#define AO_HEIGHTS " + std::to_string(std::max<size_t>(1, horizontalPlanes(scene).heights.size())));
  }
  return d;
}

AoFields::AoFields(const Scene& scene, int max_texture_units) : scene_(scene), unit_(units::aoVolume(max_texture_units)) {
  if (!ambientOcclusionSkipReason(scene).empty()) return;
  const auto t0 = Clock::now();
  fields_ = buildAoFields(scene);
  build_ms_ = msSince(t0);
  if (fields_.empty()) return;
  // One RGBA8 3D texture: per field (along z) eight blocks of n^3 texels side by side along x, one per octant
  // of normals (block b: x negative when b & 1, y when b & 2, z when b & 4), holding the occlusion for the
  // three axis normals of its signs (O(+-x), O(+-y), O(+-z), 0): a normal reads the block of its signs, one
  // trilinear lookup for the ambient cube. Filtered linearly; the shader keeps x and z inside the block.
  const size_t n = kAoVolumeSize, row = 8 * n;
  std::vector<uint8_t> texels(row * n * n * fields_.size() * 4, 0);
  for (size_t f = 0; f < fields_.size(); ++f) {
    if (fields_[f].volume.empty()) continue;
    for (size_t k = 0; k < n; ++k)
      for (size_t j = 0; j < n; ++j)
        for (size_t i = 0; i < n; ++i) {
          const uint8_t* o = &fields_[f].volume[((k * n + j) * n + i) * 8];
          for (size_t b = 0; b < 8; ++b) {
            uint8_t* t = &texels[(((f * n + k) * n + j) * row + b * n + i) * 4];
            for (size_t a = 0; a < 3; ++a) t[a] = o[2 * a + ((b >> a) & 1)];
          }
        }
  }
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_3D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, GLsizei(row), GLsizei(n), GLsizei(n * fields_.size()), 0, GL_RGBA,
               GL_UNSIGNED_BYTE, texels.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  linearClampedOneLevel(GL_TEXTURE_3D);
  glBindTexture(GL_TEXTURE_3D, 0);
  volume_bytes_ = texels.size();
  // The ground maps: one R8 2D array, per field one layer per height.
  const Planes planes = horizontalPlanes(scene);
  heights_ = planes.heights;
  mesh_height_ = planes.mesh_height;
  if (!heights_.empty()) {
    const auto t1 = Clock::now();
    const size_t g = kAoGroundSize, layer = g * g;
    std::vector<uint8_t> maps(layer * heights_.size() * fields_.size(), 0);
    for (size_t f = 0; f < fields_.size(); ++f)
      for (size_t h = 0; h < heights_.size(); ++h) {
        const std::vector<uint8_t> map = groundMap(fields_[f], heights_[h]);
        std::copy(map.begin(), map.end(), maps.begin() + std::ptrdiff_t((f * heights_.size() + h) * layer));
      }
    build_ms_ += msSince(t1);
    glGenTextures(1, &ground_texture_);
    glBindTexture(GL_TEXTURE_2D_ARRAY, ground_texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R8, GLsizei(g), GLsizei(g), GLsizei(heights_.size() * fields_.size()), 0,
                 GL_RED, GL_UNSIGNED_BYTE, maps.data());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    linearClampedOneLevel(GL_TEXTURE_2D_ARRAY);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    ground_bytes_ = maps.size();
  }
  checkGlError("uploading the ambient occlusion fields");
  receivers_ = std::make_unique<AoVertexReceivers>(scene_, fields_);
}

AoFields::~AoFields() {
  if (texture_) glDeleteTextures(1, &texture_);
  if (ground_texture_) glDeleteTextures(1, &ground_texture_);
}

void AoFields::bind(const Program& p, const Vec3& origin) const {
  if (!active()) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + unit_));
  glBindTexture(GL_TEXTURE_3D, texture_);
  if (ground_texture_) glBindTexture(GL_TEXTURE_2D_ARRAY, ground_texture_);  // the same unit, another target
  glActiveTexture(GL_TEXTURE0);
  p.set("u_ao_volume", unit_);
  p.set("u_ao_ground", unit_);
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
}

double AoFields::volumeBound(const AoField& f, const std::array<Vec3, 2>& box, const Vec3& n_world) const {
  if (f.volume.empty()) return 0;
  const Mat4 motion = occluderMotion(scene_, f.occluder);
  const Mat3 rt = glm::transpose(Mat3(motion));
  const Vec3 c(motion * Vec4(f.centre, 1.0));
  // The box's bounds in the field's frame (offsets from its centre).
  Vec3 lo(kInf), hi(-kInf);
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1 ? box[1] : box[0]).x, (k & 2 ? box[1] : box[0]).y, (k & 4 ? box[1] : box[0]).z);
    const Vec3 p = rt * (corner - c);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const Vec3 nearest = glm::clamp(Vec3(0.0), lo, hi);
  const double fade = aoFade(f.radius * f.radius / std::max(glm::dot(nearest, nearest), 1e-300));
  if (fade <= 0) return 0;
  // The channels the normal reads (ambient cube: the sign of each non-zero component).
  const Vec3 n = rt * n_world;
  int channels[3], count = 0;
  for (int a = 0; a < 3; ++a)
    if (std::abs(n[a]) > 1e-9) channels[count++] = 2 * a + (n[a] < 0);
  // The grid points trilinear lookups within the bounds interpolate (ao_field.cpp's volumeOcclusion).
  const int sz = kAoVolumeSize;
  int i0[3], i1[3];
  for (int a = 0; a < 3; ++a) {
    const auto grid = [&](double x) { return std::clamp((aoWarp(x, f.radius) + 1) / 2 * sz - 0.5, 0.0, double(sz - 1)); };
    i0[a] = int(std::floor(grid(lo[a])));
    i1[a] = int(std::ceil(grid(hi[a])));
  }
  int most = 0;
  for (int k = i0[2]; k <= i1[2]; ++k)
    for (int j = i0[1]; j <= i1[1]; ++j)
      for (int i = i0[0]; i <= i1[0]; ++i) {
        const uint8_t* o = &f.volume[((size_t(k) * sz + size_t(j)) * sz + size_t(i)) * 8];
        for (int c2 = 0; c2 < count; ++c2) most = std::max(most, int(o[channels[c2]]));
      }
  return fade * most / 255.0;
}

AoFields::Draw AoFields::receiver(size_t m, const std::array<Vec3, 2>& box, const Vec3* facing) const {
  Draw d;
  if (!active()) return d;
  d.reaches.assign(fields_.size(), 0.0f);
  const int self = scene_.meshes[m].occluder;
  bool any = false;
  for (size_t i = 0; i < fields_.size(); ++i) {
    const AoField& f = fields_[i];
    if (f.occluder == self || f.volume.empty()) continue;
    bool counts = false;
    if (facing) {
      counts = volumeBound(f, box, *facing) >= kAoNegligible;
    } else {
      const Mat4 motion = occluderMotion(scene_, f.occluder);
      const Vec3 c(motion * Vec4(f.centre, 1.0));
      const Vec3 nearest = glm::clamp(c, box[0], box[1]);
      counts = glm::dot(nearest - c, nearest - c) < f.reach * f.reach;
    }
    d.reaches[i] = counts ? 1.0f : 0.0f;
    any = any || counts;
  }
  if (!any) {
    d.reaches.clear();
    return d;
  }
  // Every occluder turning about the vertical only, not lifted: the ground maps' planes stay at their heights.
  bool upright = true;
  for (const AoField& f : fields_) {
    const Mat4 motion = occluderMotion(scene_, f.occluder);
    upright = upright && std::abs(motion[1][1] - 1) < kLevelTolerance && std::abs(motion[3][1]) < kLevelTolerance;
  }
  d.kind = upright && m < mesh_height_.size() && mesh_height_[m] >= 0 ? AoReceiver::Ground : AoReceiver::Volume;
  return d;
}

void AoFields::setReceiver(const Program& p, size_t m, const Draw& d) const {
  if (!active() || d.kind == AoReceiver::None || d.kind == AoReceiver::Screen || d.kind == AoReceiver::Vertex) return;
  for (size_t f = 0; f < fields_.size(); ++f) p.set("u_ao_reaches[" + std::to_string(f) + "]", d.reaches[f]);
  p.set("u_ao_height", m < mesh_height_.size() ? std::max(0, mesh_height_[m]) : 0);
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
  char text[384];
  std::snprintf(text, sizeof text,
                "%s %zu field%s, %d^2 positions x %d^2 directions, %.1f MB (8 bit); occlusion volumes %d^3, %.1f MB; "
                "ground maps %d^2 at %zu height%s, %.2f MB; built in %.0f ms",
                noted_ ? "reused" : "built", fields_.size(), fields_.size() == 1 ? "" : "s", a.positions, a.directions,
                double(bytes) / (1 << 20), kAoVolumeSize, double(volume_bytes_) / (1 << 20), kAoGroundSize,
                heights_.size(), heights_.size() == 1 ? "" : "s", double(ground_bytes_) / (1 << 20), build_ms_);
  std::string note = text;
  note += "; reach";  // AoField::reach: the meshes beyond it are drawn without the field
  for (const AoField& f : fields_) {
    std::snprintf(text, sizeof text, " %.1f", f.reach);
    note += text;
  }
  note += " m";
  if (receivers_) note += "; " + receivers_->note();
  stages.ran(kAmbientOcclusionStage, noted_ ? 0 : build_ms_, int(fields_.size()), note);
  noted_ = true;
}

}  // namespace pvrr::gl

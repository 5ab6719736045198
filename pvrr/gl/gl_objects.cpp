#include "pvrr/gl/gl_objects.h"

#include <string>

#include "pvrr/base/error.h"
#include "pvrr/gl/gl.h"

namespace pvrr::gl {

void CubeTarget::release() {
  if (fbo) glDeleteFramebuffers(1, &fbo);
  if (depth) glDeleteRenderbuffers(1, &depth);
  if (!colors.empty()) glDeleteTextures(GLsizei(colors.size()), colors.data());
  fbo = depth = 0;
  colors.clear();
}

void CubeTarget::create(int n, const std::vector<unsigned>& formats) {
  release();
  size = n;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  colors.resize(formats.size());
  glGenTextures(GLsizei(colors.size()), colors.data());
  for (size_t i = 0; i < formats.size(); ++i) {
    glBindTexture(GL_TEXTURE_CUBE_MAP, colors[i]);
    for (int f = 0; f < 6; ++f)
      glTexImage2D(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), 0, GLint(formats[i]), n, n, 0, GL_RGBA, GL_FLOAT, nullptr);
    // Colour, seen points (and the normals and indices of impostor mode's elements) filter linearly (see the
    // 2D maps, PvrrPass::mapTarget; followCubes decodes the blended index).
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  }
  glGenRenderbuffers(1, &depth);
  glBindRenderbuffer(GL_RENDERBUFFER, depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, n, n);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
  selectFace(0);
  std::vector<GLenum> bufs(formats.size());
  for (size_t i = 0; i < bufs.size(); ++i) bufs[i] = GLenum(GL_COLOR_ATTACHMENT0 + i);
  glDrawBuffers(GLsizei(bufs.size()), bufs.data());
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error("GL: cube-map framebuffer " + std::to_string(n) + "^2 incomplete (status " + std::to_string(status) + ")");
  checkGlError("creating a cube-map target");
}

void CubeTarget::selectFace(int face) const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  for (size_t i = 0; i < colors.size(); ++i)
    glFramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face),
                           colors[i], 0);
  glViewport(0, 0, size, size);
  const float zero[4] = {0, 0, 0, 0}, far_depth = 1.0f;
  for (size_t i = 0; i < colors.size(); ++i) glClearBufferfv(GL_COLOR, GLint(i), zero);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
}

void MeshBuffers::release() {
  if (ebo) glDeleteBuffers(1, &ebo);
  if (vbo) glDeleteBuffers(1, &vbo);
  if (vao) glDeleteVertexArrays(1, &vao);
  vao = vbo = ebo = 0;
}

void uploadMesh(MeshBuffers& mb, const std::vector<float>& data, const std::vector<int>& layout,
                const std::vector<uint32_t>& indices) {
  if (!mb.vao) {
    glGenVertexArrays(1, &mb.vao);
    glGenBuffers(1, &mb.vbo);
    glGenBuffers(1, &mb.ebo);
  }
  glBindVertexArray(mb.vao);
  glBindBuffer(GL_ARRAY_BUFFER, mb.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mb.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(), GL_DYNAMIC_DRAW);
  int stride = 0;
  for (int c : layout) stride += c;
  size_t offset = 0;
  for (size_t i = 0; i < layout.size(); ++i) {
    glEnableVertexAttribArray(GLuint(i));
    glVertexAttribPointer(GLuint(i), layout[i], GL_FLOAT, GL_FALSE, GLsizei(stride * sizeof(float)),
                          reinterpret_cast<const void*>(offset * sizeof(float)));
    offset += size_t(layout[i]);
  }
  mb.count = GLsizei(indices.size());
  glBindVertexArray(0);
}

void draw(const MeshBuffers& mb) {
  glBindVertexArray(mb.vao);
  glDrawElements(GL_TRIANGLES, mb.count, GL_UNSIGNED_INT, nullptr);
}

void uploadDataTexture(unsigned& tex, int internal_format, int w, int h, int channels, const float* data) {
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, internal_format, w, h, 0, channels == 1 ? GL_RED : GL_RGBA, GL_FLOAT, data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, 0);
}

void bindDataTextures(const Program& p, int first, std::initializer_list<std::pair<const char*, unsigned>> textures) {
  int unit = first;
  for (const auto& [name, tex] : textures) {
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_2D, tex);
    p.set(name, unit++);
  }
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace pvrr::gl

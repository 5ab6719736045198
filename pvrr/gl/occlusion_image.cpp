#include "pvrr/gl/occlusion_image.h"

#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/gl.h"

namespace pvrr::gl {

OcclusionImage::~OcclusionImage() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (image_) glDeleteTextures(1, &image_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
}

void OcclusionImage::begin() {
  glGetIntegerv(GL_VIEWPORT, viewport_);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target_);
  scissor_ = glIsEnabled(GL_SCISSOR_TEST);
  blend_ = glIsEnabled(GL_BLEND);
  const int w = (viewport_[2] + kFactor - 1) / kFactor, h = (viewport_[3] + kFactor - 1) / kFactor;
  if (w != size_[0] || h != size_[1]) {
    if (!fbo_) {
      glGenFramebuffers(1, &fbo_);
      glGenTextures(1, &image_);
      glGenRenderbuffers(1, &depth_);
    }
    glBindTexture(GL_TEXTURE_2D, image_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, w, h, 0, GL_RED, GL_UNSIGNED_BYTE, nullptr);
    linearClampedOneLevel(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, image_, 0);
    glFramebufferRenderbuffer(GL_DRAW_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    size_[0] = w;
    size_[1] = h;
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
  glViewport(0, 0, w, h);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  const float zero[4] = {0, 0, 0, 0}, far = 1;
  glClearBufferfv(GL_COLOR, 0, zero);
  glClearBufferfv(GL_DEPTH, 0, &far);
}

void OcclusionImage::end(int unit) {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(target_));
  glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  if (scissor_) glEnable(GL_SCISSOR_TEST);
  if (blend_) glEnable(GL_BLEND);
  glActiveTexture(GLenum(GL_TEXTURE0 + unit));
  glBindTexture(GL_TEXTURE_2D, image_);
  glActiveTexture(GL_TEXTURE0);
}

glm::vec4 OcclusionImage::coordinates() const {
  return glm::vec4(1.0f / float(viewport_[2]), 1.0f / float(viewport_[3]), -float(viewport_[0]) / float(viewport_[2]),
                   -float(viewport_[1]) / float(viewport_[3]));
}

}  // namespace pvrr::gl

#include "pvrr/gl/framebuffer.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>

#include "pvrr/base/error.h"
#include "pvrr/gl/gl.h"

namespace pvrr::gl {
namespace {

const char* formatName(ColorFormat f) {
  switch (f) {
    case ColorFormat::RGBA8: return "RGBA8";
    case ColorFormat::SRGB8A8: return "SRGB8_ALPHA8";
    case ColorFormat::RGBA16F: return "RGBA16F";
    case ColorFormat::RGBA32F: return "RGBA32F";
    case ColorFormat::R32F: return "R32F";
    case ColorFormat::RGBA16: return "RGBA16";
  }
  return "?";
}

GLenum internalFormat(ColorFormat f) {
  switch (f) {
    case ColorFormat::RGBA8: return GL_RGBA8;
    case ColorFormat::SRGB8A8: return GL_SRGB8_ALPHA8;
    case ColorFormat::RGBA16F: return GL_RGBA16F;
    case ColorFormat::RGBA32F: return GL_RGBA32F;
    case ColorFormat::R32F: return GL_R32F;
    case ColorFormat::RGBA16: return GL_RGBA16;
  }
  return GL_RGBA8;
}

std::string statusName(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED: return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS: return "GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS";
    case 0: return "0 (glCheckFramebufferStatus itself failed: " + glErrorName(glGetError()) + ")";
    default: {
      std::ostringstream os;
      os << "0x" << std::hex << status;
      return os.str();
    }
  }
}

GLint glInteger(GLenum name) {
  GLint v = 0;
  glGetIntegerv(name, &v);
  return v;
}

void setSampling(GLenum target, bool mipmaps) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (target == GL_TEXTURE_CUBE_MAP) glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
}

void checkImage(const ImageRGB8& image, const char* what) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw Error(std::string(what) + ": image is empty or its pixel buffer does not match " +
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  const GLint max_size = glInteger(GL_MAX_TEXTURE_SIZE);
  if (image.width > max_size || image.height > max_size) {
    throw Error(std::string(what) + ": " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_size));
  }
}

}  // namespace

// ---- Texture ----

Texture::~Texture() { release(); }

void Texture::release() noexcept {
  if (name_ != 0 && context_ != nullptr && GlContext::current() == context_) glDeleteTextures(1, &name_);
  name_ = 0;
}

Texture::Texture(Texture&& other) noexcept : name_(other.name_), target_(other.target_), context_(other.context_) {
  other.name_ = 0;
}

Texture& Texture::operator=(Texture&& other) noexcept {
  if (this != &other) {
    release();
    name_ = other.name_;
    target_ = other.target_;
    context_ = other.context_;
    other.name_ = 0;
  }
  return *this;
}

void Texture::bind(int unit) const {
  requireCurrentContext("Texture::bind");
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(target_, name_);
}

Texture createTexture2D(const ImageRGB8& image, TextureEncoding encoding, bool mipmaps) {
  requireCurrentContext("createTexture2D");
  checkImage(image, "createTexture2D");
  // GL's first row is the bottom one (t = 0): upload the image bottom row first. Stored with an opaque alpha
  // (SRGB8_ALPHA8 / RGBA8): the same values as a 3-byte format, but llvmpipe fetches 4-byte texels faster
  // (docs/method.md "Measurements behind the design").
  const std::size_t w = static_cast<std::size_t>(image.width), h = static_cast<std::size_t>(image.height);
  std::vector<std::uint8_t> flipped(4 * w * h);
  for (std::size_t y = 0; y < h; ++y) {
    const std::uint8_t* src = &image.rgb[3 * y * w];
    std::uint8_t* dst = &flipped[4 * (h - 1 - y) * w];
    for (std::size_t x = 0; x < w; ++x) {
      dst[4 * x] = src[3 * x];
      dst[4 * x + 1] = src[3 * x + 1];
      dst[4 * x + 2] = src[3 * x + 2];
      dst[4 * x + 3] = 255;
    }
  }
  GLuint name = 0;
  glGenTextures(1, &name);
  Texture texture(name, GL_TEXTURE_2D, GlContext::current());
  glBindTexture(GL_TEXTURE_2D, name);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, encoding == TextureEncoding::Srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, image.width,
               image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, flipped.data());
  if (mipmaps) glGenerateMipmap(GL_TEXTURE_2D);
  setSampling(GL_TEXTURE_2D, mipmaps);
  checkGlError("createTexture2D");
  return texture;
}

Texture createCubeMap(const std::array<ImageRGB8, 6>& faces, TextureEncoding encoding, bool mipmaps) {
  requireCurrentContext("createCubeMap");
  for (const auto& f : faces) {
    checkImage(f, "createCubeMap");
    if (f.width != f.height || f.width != faces[0].width) {
      throw Error("createCubeMap: faces must be square and of one size; got " + std::to_string(f.width) + "x" +
                  std::to_string(f.height) + " beside " + std::to_string(faces[0].width) + "x" +
                  std::to_string(faces[0].height));
    }
  }
  GLuint name = 0;
  glGenTextures(1, &name);
  Texture texture(name, GL_TEXTURE_CUBE_MAP, GlContext::current());
  glBindTexture(GL_TEXTURE_CUBE_MAP, name);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < 6; ++i) {
    glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + static_cast<GLenum>(i), 0,
                 encoding == TextureEncoding::Srgb ? GL_SRGB8 : GL_RGB8, faces[i].width, faces[i].height, 0, GL_RGB,
                 GL_UNSIGNED_BYTE, faces[i].rgb.data());
  }
  if (mipmaps) glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
  setSampling(GL_TEXTURE_CUBE_MAP, mipmaps);
  checkGlError("createCubeMap");
  return texture;
}

// ---- Framebuffer ----

Framebuffer::Framebuffer(int width, int height, const std::vector<ColorFormat>& colors, DepthFormat depth)
    : width_(width), height_(height), colors_(colors) {
  requireCurrentContext("Framebuffer");
  context_ = GlContext::current();
  const std::string label = "Framebuffer " + std::to_string(width) + "x" + std::to_string(height);
  const GLint max_size = std::min(glInteger(GL_MAX_TEXTURE_SIZE), glInteger(GL_MAX_RENDERBUFFER_SIZE));
  if (width <= 0 || height <= 0 || width > max_size || height > max_size) {
    throw Error(label + ": each side must be in 1.." + std::to_string(max_size) + " pixels");
  }
  const GLint max_attachments = std::min(glInteger(GL_MAX_COLOR_ATTACHMENTS), glInteger(GL_MAX_DRAW_BUFFERS));
  if (static_cast<GLint>(colors.size()) > max_attachments) {
    throw Error(label + ": " + std::to_string(colors.size()) + " colour attachments requested, the context allows " +
                std::to_string(max_attachments));
  }

  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  color_textures_.assign(colors.size(), 0);
  if (!colors.empty()) glGenTextures(static_cast<GLsizei>(colors.size()), color_textures_.data());
  for (std::size_t i = 0; i < colors.size(); ++i) {
    glBindTexture(GL_TEXTURE_2D, color_textures_[i]);
    // No data is uploaded, so format/type only need to be a valid pair for the internal format.
    const GLenum type = colors[i] == ColorFormat::RGBA8 || colors[i] == ColorFormat::SRGB8A8 ? GL_UNSIGNED_BYTE : GL_FLOAT;
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internalFormat(colors[i])), width, height, 0,
                 colors[i] == ColorFormat::R32F ? GL_RED : GL_RGBA, type, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i), GL_TEXTURE_2D,
                           color_textures_[i], 0);
  }
  if (depth != DepthFormat::None) {
    glGenTextures(1, &depth_texture_);
    glBindTexture(GL_TEXTURE_2D, depth_texture_);
    if (depth == DepthFormat::Depth24) {
      glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, width, height, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT,
                   nullptr);
    } else {
      glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_texture_, 0);
  }
  std::vector<GLenum> draw_buffers(colors.size());
  for (std::size_t i = 0; i < colors.size(); ++i) draw_buffers[i] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
  if (draw_buffers.empty()) {
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
  } else {
    glDrawBuffers(static_cast<GLsizei>(draw_buffers.size()), draw_buffers.data());
  }
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    std::string formats;
    for (auto f : colors) formats += (formats.empty() ? "" : ", ") + std::string(formatName(f));
    const std::string depth_name =
        depth == DepthFormat::None ? "none" : (depth == DepthFormat::Depth24 ? "DEPTH24" : "DEPTH32F");
    release();
    throw Error(label + " (colour [" + formats + "], depth " + depth_name + ") is incomplete: " + statusName(status));
  }
  try {
    checkGlError(label.c_str());
  } catch (...) {
    release();
    throw;
  }
}

Framebuffer::~Framebuffer() { release(); }

Framebuffer Framebuffer::defaultOfCurrentContext(int width, int height) {
  requireCurrentContext("Framebuffer::defaultOfCurrentContext");
  if (width <= 0 || height <= 0) throw Error("Framebuffer::defaultOfCurrentContext: each side must be at least 1 pixel");
  Framebuffer f;
  f.width_ = width;
  f.height_ = height;
  f.colors_ = {ColorFormat::SRGB8A8};
  f.color_textures_ = {0};
  f.context_ = GlContext::current();
  f.default_ = true;
  return f;
}

void Framebuffer::release() noexcept {
  if (context_ != nullptr && GlContext::current() == context_ && !default_) {
    if (fbo_ != 0) glDeleteFramebuffers(1, &fbo_);
    if (!color_textures_.empty()) {
      glDeleteTextures(static_cast<GLsizei>(color_textures_.size()), color_textures_.data());
    }
    if (depth_texture_ != 0) glDeleteTextures(1, &depth_texture_);
  }
  fbo_ = 0;
  color_textures_.clear();
  depth_texture_ = 0;
  default_ = false;
}

Framebuffer::Framebuffer(Framebuffer&& other) noexcept
    : width_(other.width_), height_(other.height_), colors_(std::move(other.colors_)), fbo_(other.fbo_),
      color_textures_(std::move(other.color_textures_)), depth_texture_(other.depth_texture_),
      context_(other.context_), default_(other.default_) {
  other.default_ = false;
  other.fbo_ = 0;
  other.color_textures_.clear();
  other.depth_texture_ = 0;
}

Framebuffer& Framebuffer::operator=(Framebuffer&& other) noexcept {
  if (this != &other) {
    release();
    width_ = other.width_;
    height_ = other.height_;
    colors_ = std::move(other.colors_);
    fbo_ = other.fbo_;
    color_textures_ = std::move(other.color_textures_);
    depth_texture_ = other.depth_texture_;
    context_ = other.context_;
    default_ = other.default_;
    other.default_ = false;
    other.fbo_ = 0;
    other.color_textures_.clear();
    other.depth_texture_ = 0;
  }
  return *this;
}

void Framebuffer::bind() const {
  requireCurrentContext("Framebuffer::bind");
  if (fbo_ == 0 && !default_) throw Error("Framebuffer::bind: framebuffer was moved from");
  if (GlContext::current() != context_) throw Error("Framebuffer::bind: framebuffer belongs to another GL context");
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  if (default_) glDrawBuffer(GL_BACK);
  glViewport(0, 0, width_, height_);
}

void Framebuffer::clear(const std::array<float, 4>& rgba, float depth) const {
  bind();
  for (std::size_t i = 0; i < colors_.size(); ++i) glClearBufferfv(GL_COLOR, static_cast<GLint>(i), rgba.data());
  if (depth_texture_ != 0 || default_) glClearBufferfv(GL_DEPTH, 0, &depth);
}

void Framebuffer::clearDepth(float depth) const {
  bind();
  if (depth_texture_ != 0 || default_) glClearBufferfv(GL_DEPTH, 0, &depth);
}

void Framebuffer::bindRegion(int width, int height) const {
  if (width <= 0 || height <= 0 || width > width_ || height > height_)
    throw Error("Framebuffer::bindRegion: region " + std::to_string(width) + "x" + std::to_string(height) +
                " outside the framebuffer's " + std::to_string(width_) + "x" + std::to_string(height_));
  bind();
  glViewport(0, 0, width, height);
}

void Framebuffer::bindRegionClearDepth(int width, int height, float depth) const {
  bindRegion(width, height);
  if (depth_texture_ == 0 && !default_) return;
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, width, height);
  glClearBufferfv(GL_DEPTH, 0, &depth);
  glDisable(GL_SCISSOR_TEST);
}

ColorFormat Framebuffer::colorFormat(int attachment) const {
  checkAttachment(attachment);
  return colors_[static_cast<std::size_t>(attachment)];
}

unsigned int Framebuffer::colorTexture(int attachment) const {
  checkAttachment(attachment);
  return color_textures_[static_cast<std::size_t>(attachment)];
}

void Framebuffer::checkAttachment(int attachment) const {
  if (attachment < 0 || attachment >= static_cast<int>(colors_.size())) {
    throw Error("Framebuffer: colour attachment " + std::to_string(attachment) + " requested, it has " +
                std::to_string(colors_.size()));
  }
}

void Framebuffer::readInto(int attachment, unsigned int type, void* pixels, std::size_t bytes_per_pixel) const {
  checkAttachment(attachment);
  if (default_) throw Error("Framebuffer: the default framebuffer is not read back here");
  bind();
  glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, type, pixels);
  checkGlError("Framebuffer readback");
  // GL returns the bottom row first; swap rows in place to make them top-down.
  const std::size_t row = bytes_per_pixel * static_cast<std::size_t>(width_);
  auto* bytes = static_cast<unsigned char*>(pixels);
  std::vector<unsigned char> tmp(row);
  for (int y = 0; y < height_ / 2; ++y) {
    unsigned char* top = bytes + static_cast<std::size_t>(y) * row;
    unsigned char* bottom = bytes + static_cast<std::size_t>(height_ - 1 - y) * row;
    std::memcpy(tmp.data(), top, row);
    std::memcpy(top, bottom, row);
    std::memcpy(bottom, tmp.data(), row);
  }
}

std::vector<std::uint8_t> Framebuffer::readRGBA8(int attachment) const {
  std::vector<std::uint8_t> out(4 * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  readInto(attachment, GL_UNSIGNED_BYTE, out.data(), 4);
  return out;
}

std::vector<float> Framebuffer::readFloat4(int attachment) const {
  std::vector<float> out(4 * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  readInto(attachment, GL_FLOAT, out.data(), 4 * sizeof(float));
  return out;
}

}  // namespace pvrr::gl

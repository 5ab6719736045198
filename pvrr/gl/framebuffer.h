// Offscreen render targets (framebuffer objects of explicit size) with top-down readback, and textures made from
// CPU images. Everything here needs a current pvrr::gl::GlContext; objects are deleted only while the context
// that made them is current (destroy them before their context).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "pvrr/base/image.h"

namespace pvrr::gl {

class GlContext;

enum class ColorFormat { RGBA8, SRGB8A8, RGBA16F, RGBA32F, R32F, RGBA16 };
enum class DepthFormat { None, Depth24, Depth32F };

// How texture data from 8-bit images is interpreted when sampled: Srgb stores GL_SRGB8_ALPHA8 (sampling returns
// linear values), Linear stores GL_RGBA8 (sampling returns code / 255); alpha is 1.
enum class TextureEncoding { Srgb, Linear };

// An owned GL texture name.
class Texture {
 public:
  Texture() = default;
  ~Texture();
  Texture(Texture&& other) noexcept;
  Texture& operator=(Texture&& other) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;

  unsigned int name() const { return name_; }
  unsigned int target() const { return target_; }  // GL_TEXTURE_2D or GL_TEXTURE_CUBE_MAP
  // Binds the texture to texture unit `unit` (glActiveTexture(GL_TEXTURE0 + unit)).
  void bind(int unit) const;

 private:
  friend Texture createTexture2D(const ImageRGB8&, TextureEncoding, bool);
  friend Texture createCubeMap(const std::array<ImageRGB8, 6>&, TextureEncoding, bool);
  Texture(unsigned int name, unsigned int target, GlContext* context)
      : name_(name), target_(target), context_(context) {}
  void release() noexcept;

  unsigned int name_ = 0, target_ = 0;
  GlContext* context_ = nullptr;
};

// A 2D texture from an 8-bit image. The image's rows are top-down; the texture follows GL's convention, so
// t = 0 is the BOTTOM row of the image and t = 1 its top. Filtering: trilinear with mipmaps (generated) or
// bilinear without; wrap: clamp to edge.
Texture createTexture2D(const ImageRGB8& image, TextureEncoding encoding = TextureEncoding::Srgb,
                        bool mipmaps = true);

// A cube map from six square images of the same size in GL's face order +X, -X, +Y, -Y, +Z, -Z. Each face is
// uploaded as stored (row 0 first), which is the orientation GL's cube-map lookup expects from top-down images.
Texture createCubeMap(const std::array<ImageRGB8, 6>& faces, TextureEncoding encoding = TextureEncoding::Srgb,
                      bool mipmaps = true);

class Framebuffer {
 public:
  // A framebuffer of width x height pixels with one texture per entry of `colors` (attachment i =
  // GL_COLOR_ATTACHMENTi, fragment output location i) and an optional depth texture. Attachments use nearest
  // filtering and clamp to edge. Throws pvrr::Error for a bad size or attachment count, or when GL reports the
  // framebuffer incomplete (naming the status, e.g. GL_FRAMEBUFFER_UNSUPPORTED).
  Framebuffer(int width, int height, const std::vector<ColorFormat>& colors,
              DepthFormat depth = DepthFormat::Depth24);
  // The current context's default framebuffer (a window's back buffer) as a target of width x height pixels:
  // bind() binds framebuffer 0 and draws into GL_BACK; it owns nothing. One colour attachment (colorFormat(0)
  // SRGB8A8, colorTexture(0) 0: there is no texture to read) and a depth attachment cleared as any other; their
  // real formats are the window's, which the caller checks (app/view/window.h). No readback (readRGBA8,
  // readFloat4 throw).
  static Framebuffer defaultOfCurrentContext(int width, int height);
  ~Framebuffer();
  Framebuffer(Framebuffer&& other) noexcept;
  Framebuffer& operator=(Framebuffer&& other) noexcept;
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  // Binds for drawing and reading, sets the viewport to the whole framebuffer and enables all colour attachments
  // as draw buffers.
  void bind() const;
  // Clears every colour attachment to `rgba` and the depth attachment to `depth`. Binds the framebuffer.
  void clear(const std::array<float, 4>& rgba, float depth = 1.0f) const;
  // Clears only the depth attachment (a pass that writes every pixel, e.g. one ending with a full-screen sky,
  // needs no colour clear, which costs llvmpipe a full pass over the target). Binds the framebuffer.
  void clearDepth(float depth = 1.0f) const;
  // Binds like bind(), with the viewport on the lower-left width x height pixels only (a map rendered into part
  // of its texture). Throws pvrr::Error when the region does not fit.
  void bindRegion(int width, int height) const;
  // bindRegion, then clears the depth of that region only (a scissored clear): a map drawn into part of its
  // texture need not clear the rest (llvmpipe clears every tile of a full clear).
  void bindRegionClearDepth(int width, int height, float depth) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int colorCount() const { return static_cast<int>(colors_.size()); }
  ColorFormat colorFormat(int attachment) const;
  unsigned int fboName() const { return fbo_; }
  unsigned int colorTexture(int attachment) const;
  unsigned int depthTexture() const { return depth_texture_; }  // 0 with DepthFormat::None
  bool isDefault() const { return default_; }                  // defaultOfCurrentContext

  // The attachment's pixels as RGBA8, width * height * 4 bytes, rows TOP-DOWN (GL's bottom-up rows flipped).
  // Float attachments are clamped to [0, 1] and converted by GL. Leaves this framebuffer bound for reading.
  std::vector<std::uint8_t> readRGBA8(int attachment = 0) const;
  // The attachment's pixels as RGBA floats, width * height * 4 values, rows TOP-DOWN. RGBA8 attachments read as
  // code / 255.
  std::vector<float> readFloat4(int attachment = 0) const;

 private:
  Framebuffer() = default;
  void checkAttachment(int attachment) const;
  void readInto(int attachment, unsigned int type, void* pixels, std::size_t bytes_per_pixel) const;
  void release() noexcept;

  int width_ = 0, height_ = 0;
  std::vector<ColorFormat> colors_;
  unsigned int fbo_ = 0;
  std::vector<unsigned int> color_textures_;
  unsigned int depth_texture_ = 0;
  GlContext* context_ = nullptr;
  bool default_ = false;  // framebuffer 0 of context_ (fbo_ stays 0, nothing owned)
};

}  // namespace pvrr::gl

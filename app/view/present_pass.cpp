#include "app/view/present_pass.h"

#include "pvrr/gl/gl.h"  // glad first

#include <algorithm>
#include <array>

#include "app/view/window.h"
#include "pvrr/base/error.h"
#include "pvrr/base/image.h"

namespace pvrr::app::view {
namespace {

// The uniform buffer binding point of SrgbBuckets: the viewer's GL uses no other uniform block.
constexpr unsigned kSrgbBucketsBinding = 0;
constexpr int kBuckets = 4096, kBucketValues = 16;

}  // namespace

std::vector<std::uint32_t> srgbBucketWords() {
  std::vector<std::uint32_t> words(kBuckets / 2, 0);
  for (int j = 0; j < kBuckets; ++j) {
    // The code of each 16-bit value, as the table of 65536 this replaces held it.
    std::array<int, kBucketValues> code{};
    for (int i = 0; i < kBucketValues; ++i)
      code[size_t(i)] = linearToSrgb8(double(float(j * kBucketValues + i) / 65535.0f));
    int step = kBucketValues;
    for (int i = 1; i < kBucketValues; ++i)
      if (code[size_t(i)] != code[0]) {
        step = i;
        break;
      }
    for (int i = step; i < kBucketValues; ++i)
      PVRR_CHECK(code[size_t(i)] == code[0] + 1, "sRGB bucket " << j << " steps more than once");
    const std::uint32_t bucket = std::uint32_t(code[0]) | (std::uint32_t(step) << 8);
    words[size_t(j / 2)] |= bucket << (16 * (j & 1));
  }
  return words;
}

int srgbCodeFromBuckets(const std::vector<std::uint32_t>& words, int k) {
  const int j = k >> 4;
  const std::uint32_t bucket = (words[size_t(j >> 1)] >> (16 * (j & 1))) & 0xFFFFu;
  return int(bucket & 255u) + (std::uint32_t(k & 15) >= (bucket >> 8) ? 1 : 0);
}

PresentPass::PresentPass(unsigned empty_vao)
    : program_(gl::Program::fromSources({"full-screen triangle (app/view/window.cpp)", kFullScreenVs},
                                        gl::shaderWithIncludes("present.frag"))),
      vao_(empty_vao) {
  bindBlockOf(program_.id());
  const std::vector<std::uint32_t> words = srgbBucketWords();
  glGenBuffers(1, &table_);
  glBindBuffer(GL_UNIFORM_BUFFER, table_);
  glBufferData(GL_UNIFORM_BUFFER, GLsizeiptr(words.size() * sizeof(std::uint32_t)), words.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_UNIFORM_BUFFER, 0);
  gl::checkGlError("creating the present pass");
}

PresentPass::~PresentPass() {
  if (table_) glDeleteBuffers(1, &table_);
}

void PresentPass::bindBlockOf(unsigned program) {
  const GLuint block = glGetUniformBlockIndex(program, "SrgbBuckets");
  PVRR_CHECK(block != GL_INVALID_INDEX, "a present program without the SrgbBuckets block");
  glUniformBlockBinding(program, block, kSrgbBucketsBinding);
}

void PresentPass::bindTable() const { glBindBufferBase(GL_UNIFORM_BUFFER, kSrgbBucketsBinding, table_); }

void PresentPass::present(unsigned texture, int width, int height, const std::optional<PixelRect>& hole) const {
  beginPresentPass(width, height);
  program_.use();
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glUniform1i(program_.uniformLocation("u_frame"), 0);
  bindTable();
  glBindVertexArray(vao_);
  PixelRect h = hole.value_or(PixelRect{});
  h = {std::clamp(h.x0, 0, width), std::clamp(h.y0, 0, height), std::clamp(h.x1, 0, width), std::clamp(h.y1, 0, height)};
  if (h.empty()) {
    glDrawArrays(GL_TRIANGLES, 0, 3);
  } else {
    // The window less the hole, as up to four scissor boxes (GL's rows bottom-up): the columns left and right
    // of it, and above and below it between them.
    glEnable(GL_SCISSOR_TEST);
    const std::array<std::array<int, 4>, 4> boxes{{{0, 0, h.x0, height},
                                                   {h.x1, 0, width - h.x1, height},
                                                   {h.x0, 0, h.x1 - h.x0, height - h.y1},
                                                   {h.x0, height - h.y0, h.x1 - h.x0, h.y0}}};
    for (const auto& b : boxes) {
      if (b[2] <= 0 || b[3] <= 0) continue;
      glScissor(b[0], b[1], b[2], b[3]);
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_SCISSOR_TEST);
  }
  glBindVertexArray(0);
  gl::checkGlError("presenting the frame");
}

}  // namespace pvrr::app::view

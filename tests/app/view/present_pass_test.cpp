// The present pass's sRGB table (app/view/present_pass.h): its bucket encode, as the shader reads it
// (shaders/srgb_encode.glsl), is pvrr::linearToSrgb8 of every 16-bit value, as the 65536-entry table it replaced
// held it. (The GL side is checked by the window tests: screenshots against pvrr render.)
#include <gtest/gtest.h>

#include "app/view/present_pass.h"
#include "pvrr/base/image.h"

namespace pvrr::app::view {
namespace {

TEST(PresentPass, BucketEncodeIsTheExactEncodeOfEvery16BitValue) {
  const std::vector<std::uint32_t> words = srgbBucketWords();
  ASSERT_EQ(words.size() * sizeof(std::uint32_t), 8192u);  // the shader's uvec4[512]
  for (int k = 0; k < 65536; ++k)
    ASSERT_EQ(srgbCodeFromBuckets(words, k), int(linearToSrgb8(double(float(k) / 65535.0f)))) << "k = " << k;
}

}  // namespace
}  // namespace pvrr::app::view

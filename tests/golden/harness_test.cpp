// The golden-image harness itself (support/golden.h), without GL: an in-tree reference compared with altered
// copies of itself, at the edges of each threshold, and the failure's diff images. Uses the reference
// plane-mirror-raster (160 x 120 = 19,200 pixels).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "support/golden.h"

namespace pvrr {
namespace {

const char* const kName = "plane-mirror-raster";

ImageRGB8 reference() { return readPng(std::string(PVRR_SOURCE_DIR) + "/tests/golden/images/" + kName + ".png"); }

// Adds `delta` to every channel of the first `pixels` pixels (row-major from the top), clamped to 0..255.
ImageRGB8 shifted(ImageRGB8 img, size_t pixels, int delta) {
  for (size_t i = 0; i < 3 * pixels && i < img.rgb.size(); ++i)
    img.rgb[i] = uint8_t(std::clamp(int(img.rgb[i]) + delta, 0, 255));
  return img;
}

class GoldenHarness : public ::testing::Test {
 protected:
  void SetUp() override {
    if (test::updatingGoldens()) GTEST_SKIP() << "PVRR_UPDATE_GOLDEN is set: these checks would rewrite a reference";
  }
};

TEST_F(GoldenHarness, ItsOwnReferenceMatches) { EXPECT_TRUE(test::matchesGolden(kName, reference())); }

TEST_F(GoldenHarness, FailingFractionIsTheLimitForPixelsOverTheDelta) {
  const ImageRGB8 ref = reference();
  const size_t total = size_t(ref.width) * size_t(ref.height);
  const size_t allowed = size_t(test::kGoldenTolerance.failing_fraction * double(total));  // 96
  // Pixels changed by far more than pixel_delta (edges flipping between surfaces): up to the fraction they
  // pass whatever their size, one more fails.
  auto flipped = [&](size_t n) {
    ImageRGB8 img = ref;
    for (size_t i = 0; i < 3 * n; ++i) img.rgb[i] = img.rgb[i] < 128 ? 255 : 0;  // at least 128 codes off
    return img;
  };
  EXPECT_TRUE(test::matchesGolden(kName, flipped(allowed)));
  EXPECT_FALSE(test::matchesGolden(kName, flipped(allowed + 1)));
}

TEST_F(GoldenHarness, MeanDeltaCatchesABroadChangeUnderThePixelDelta) {
  const ImageRGB8 ref = reference();
  const size_t total = size_t(ref.width) * size_t(ref.height);
  // Every pixel one code darker: the mean is about 1 (clamping keeps black pixels black; the assertion checks
  // that few are), over the 0.3 allowed.
  ImageRGB8 darker = shifted(ref, total, -1);
  ASSERT_GT(test::meanWithinTolerance(ref, darker, test::kGoldenTolerance.pixel_delta), 0.5);
  EXPECT_FALSE(test::matchesGolden(kName, darker));
  // A tenth of the pixels 2 codes darker: a mean of at most 0.2 passes.
  ImageRGB8 some = shifted(ref, total / 10, -2);
  ASSERT_LE(test::meanWithinTolerance(ref, some, test::kGoldenTolerance.pixel_delta), 0.2);
  EXPECT_TRUE(test::matchesGolden(kName, some));
}

TEST_F(GoldenHarness, AFailureWritesActualReferenceAndDiffImages) {
  const std::filesystem::path dir = PVRR_GOLDEN_DIFF_DIR;
  for (const char* suffix : {"-actual.png", "-reference.png", "-diff.png"})
    std::filesystem::remove(dir / (std::string(kName) + suffix));
  const ImageRGB8 ref = reference();
  // The top 40 rows 40 codes darker (ASSERT: they are not black).
  const ::testing::AssertionResult r = test::matchesGolden(kName, shifted(ref, size_t(ref.width) * 40, -40));
  ASSERT_FALSE(r);
  for (const char* suffix : {"-actual.png", "-reference.png", "-diff.png"}) {
    const std::filesystem::path p = dir / (std::string(kName) + suffix);
    EXPECT_TRUE(std::filesystem::exists(p)) << p;
    EXPECT_NE(std::string(r.message()).find(p.string()), std::string::npos) << "the message names " << p;
  }
  EXPECT_EQ(readPng((dir / (std::string(kName) + "-reference.png")).string()).rgb, ref.rgb);
}

TEST_F(GoldenHarness, WrongSizeAndMissingReferenceFail) {
  EXPECT_FALSE(test::matchesGolden(kName, ImageRGB8(16, 12)));
  const ::testing::AssertionResult missing = test::matchesGolden("no-such-golden", ImageRGB8(16, 12));
  EXPECT_FALSE(missing);
  EXPECT_NE(std::string(missing.message()).find("PVRR_UPDATE_GOLDEN=1"), std::string::npos);
  EXPECT_FALSE(test::matchesGolden("../escape", ImageRGB8(16, 12)));
}

}  // namespace
}  // namespace pvrr

// pvrr/base/image.h: PNG round trip, atomic writes, the sRGB curve and the image comparator.
#include "pvrr/base/image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pvrr/base/error.h"
#include "support/temp_dir.h"

namespace pvrr {
namespace {

namespace fs = std::filesystem;

using test::TempDir;

ImageRGB8 gradient(int w, int h) {
  ImageRGB8 image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      image.at(x, y)[0] = static_cast<std::uint8_t>((37 * x + 11 * y) % 256);
      image.at(x, y)[1] = static_cast<std::uint8_t>((5 * x * y) % 256);
      image.at(x, y)[2] = static_cast<std::uint8_t>(255 - (x + y) % 256);
    }
  }
  return image;
}

TEST(Image, PngRoundTripIsExactAndKeepsRowOrder) {
  TempDir dir;
  const ImageRGB8 image = gradient(33, 17);  // odd sizes: rows of 99 bytes
  const std::string path = (dir.path() / "round.png").string();
  writePngAtomic(path, image);
  const ImageRGB8 back = readPng(path);
  EXPECT_EQ(back.width, 33);
  EXPECT_EQ(back.height, 17);
  EXPECT_EQ(back.rgb, image.rgb);
  EXPECT_EQ(dir.entries(), 1u) << "temporary file left behind";
  // Overwriting an existing file replaces it whole.
  const ImageRGB8 other = gradient(5, 3);
  writePngAtomic(path, other);
  EXPECT_EQ(readPng(path).rgb, other.rgb);
  EXPECT_EQ(dir.entries(), 1u);
}

TEST(Image, AtomicWriteIntoAMissingFolderFailsAndLeavesNothing) {
  TempDir dir;
  const fs::path missing = dir.path() / "no-such-folder";
  const std::string path = (missing / "out.png").string();
  try {
    writePngAtomic(path, gradient(4, 4));
    FAIL() << "write into a missing folder succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_EQ(dir.entries(), 0u);
}

TEST(Image, FailedRenameRemovesTheTemporaryAndKeepsTheTarget) {
  TempDir dir;
  // A non-empty directory at the target path: the PNG is written, then rename() must fail.
  const fs::path target = dir.path() / "occupied.png";
  fs::create_directory(target);
  std::ofstream(target / "keep.txt") << "x";
  EXPECT_THROW(writePngAtomic(target.string(), gradient(3, 3)), Error);
  EXPECT_EQ(dir.entries(), 1u) << "temporary file left behind";
  EXPECT_TRUE(fs::is_directory(target));
}

TEST(Image, ReadingAMissingOrCorruptFileNamesThePath) {
  TempDir dir;
  const std::string missing = (dir.path() / "missing.png").string();
  try {
    readPng(missing);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string corrupt = (dir.path() / "corrupt.png").string();
  std::ofstream(corrupt) << "not a png at all";
  try {
    readPng(corrupt);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(corrupt), std::string::npos) << e.what();
  }
}

TEST(Image, SrgbCurveMatchesTheStandardAndInverts) {
  // IEC 61966-2-1 values: the curve is continuous at its threshold to within the standard's rounding of 0.04045
  // (the two pieces meet at 0.0031308 * 12.92 = 0.040450); mid grey 0.5 encodes 0.21404 linear.
  constexpr double kPublishedDigits = 1e-5;  // the standard's constants have 5-6 significant digits
  EXPECT_NEAR(srgbToLinear(0.5), 0.214041, kPublishedDigits);
  EXPECT_NEAR(linearToSrgb(0.0031308), 0.04045, kPublishedDigits);
  EXPECT_DOUBLE_EQ(srgbToLinear(0.0), 0.0);
  EXPECT_DOUBLE_EQ(srgbToLinear(1.0), 1.0);
  EXPECT_NEAR(linearToSrgb(1.0), 1.0, 1e-15);
  // Round trip over the whole range (both sides computed in double; 1e-12 is rounding, not model error).
  constexpr double kRoundTrip = 1e-12;
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    EXPECT_NEAR(linearToSrgb(srgbToLinear(v)), v, kRoundTrip) << v;
  }
  // Every 8-bit code survives code -> linear -> code.
  for (int c = 0; c < 256; ++c) EXPECT_EQ(linearToSrgb8(srgb8ToLinear(static_cast<std::uint8_t>(c))), c);
  EXPECT_EQ(linearToSrgb8(-1.0), 0);
  EXPECT_EQ(linearToSrgb8(7.0), 255);
  const ImageRGB8 g = gradient(7, 5);
  EXPECT_EQ(toSrgb8(toLinear(g)).rgb, g.rgb);
}

TEST(Image, ComparatorCountsMaxMeanAndFailingPixels) {
  ImageRGB8 a = gradient(10, 4);  // 40 pixels
  ImageRGB8 b = a;
  ImageDiff same = compareImages(a, b, 0);
  EXPECT_EQ(same.max_abs, 0);
  EXPECT_EQ(same.mean_abs, 0);
  EXPECT_EQ(same.failing_pixels, 0);
  EXPECT_EQ(same.width, 10);
  EXPECT_EQ(same.height, 4);

  // Two pixels changed: one by 3 in one channel, one by 10 in two channels.
  auto bump = [](std::uint8_t& v, int d) { v = static_cast<std::uint8_t>(v >= 128 ? v - d : v + d); };
  bump(b.at(2, 1)[0], 3);
  bump(b.at(9, 3)[1], 10);
  bump(b.at(9, 3)[2], 10);
  const ImageDiff d = compareImages(a, b, 3);  // 3 is not over the tolerance of 3
  EXPECT_EQ(d.max_abs, 10);
  EXPECT_DOUBLE_EQ(d.mean_abs, (3.0 + 10 + 10) / (3 * 40));
  EXPECT_EQ(d.failing_pixels, 1);
  EXPECT_DOUBLE_EQ(d.failing_fraction, 1.0 / 40);
  EXPECT_EQ(compareImages(a, b, 2).failing_pixels, 2);
  EXPECT_EQ(compareImages(a, b, 10).failing_pixels, 0);
  EXPECT_NE(describe(d).find("1 of 40 pixels"), std::string::npos) << describe(d);

  EXPECT_THROW(compareImages(a, gradient(4, 10), 0), Error);

  ImageRGBf fa(2, 1), fb(2, 1);
  fb.at(1, 0)[2] = 0.25f;
  const ImageDiff df = compareImages(fa, fb, 0.1);
  EXPECT_DOUBLE_EQ(df.max_abs, 0.25);
  EXPECT_DOUBLE_EQ(df.failing_fraction, 0.5);
}

TEST(Image, DiffImageMarksExactlyTheDifferingPixels) {
  const ImageRGB8 a = gradient(6, 3);
  ImageRGB8 b = a;
  b.at(4, 2)[1] = static_cast<std::uint8_t>(b.at(4, 2)[1] ^ 0x40);  // a difference of 64: full red
  const ImageRGB8 diff = diffImage(a, b);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 6; ++x) {
      const std::uint8_t* p = diff.at(x, y);
      if (x == 4 && y == 2) {
        EXPECT_EQ(p[0], 255);
        EXPECT_EQ(p[1], 0);
        EXPECT_EQ(p[2], 0);
      } else {
        EXPECT_TRUE(p[0] == p[1] && p[1] == p[2]) << "unchanged pixel " << x << "," << y << " is not grey";
        EXPECT_LE(p[0], 77) << "context grey brighter than 30% of white";
      }
    }
  }
  TempDir dir;
  const std::string path = (dir.path() / "diff.png").string();
  writeDiffImage(a, b, path);
  EXPECT_EQ(readPng(path).rgb, diff.rgb);
}

TEST(Image, RgbFromRgbaDropsAlpha) {
  const std::vector<std::uint8_t> rgba = {1, 2, 3, 4, 5, 6, 7, 8};
  const ImageRGB8 image = rgbFromRgba(2, 1, rgba);
  EXPECT_EQ(image.rgb, (std::vector<std::uint8_t>{1, 2, 3, 5, 6, 7}));
}

}  // namespace
}  // namespace pvrr

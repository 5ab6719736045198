// Procedural textures: deterministic, and each has the structure its name promises. Set
// PVRR_WRITE_TEXTURES=<folder> to also write every texture as a PPM there for a look.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <set>

#include "pvrr/base/error.h"
#include "pvrr/base/image.h"
#include "pvrr/scene/texture_gen.h"

namespace pvrr {
namespace {

using Rgb = std::array<int, 3>;

Rgb pixel(const TextureImage& img, int x, int y) {
  const uint8_t* p = img.at(x, y);
  return {p[0], p[1], p[2]};
}
Rgb code(const Vec3& linear) { return {linearToSrgb8(linear.x), linearToSrgb8(linear.y), linearToSrgb8(linear.z)}; }
// Rec. 709 luma of the codes: enough to tell ink from paper, markings from asphalt.
double luma(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

void maybeWrite(const TextureImage& img, const std::string& name) {
  const char* dir = std::getenv("PVRR_WRITE_TEXTURES");
  if (!dir) return;
  std::ofstream out(std::string(dir) + "/" + name + ".ppm", std::ios::binary);
  out << "P6\n" << img.width << " " << img.height << "\n255\n";
  out.write(reinterpret_cast<const char*>(img.rgb.data()), static_cast<std::streamsize>(img.rgb.size()));
}

TextureDesc desc(TextureDesc::Kind kind, int w, int h, Vec3 a, Vec3 b) {
  TextureDesc d;
  d.kind = kind;
  d.width = w;
  d.height = h;
  d.color_a = a;
  d.color_b = b;
  return d;
}

// Runs of consecutive indices where pred holds: (first, one past last).
template <class Pred>
std::vector<std::pair<int, int>> runs(int n, Pred pred) {
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < n; ++i) {
    if (!pred(i)) continue;
    int j = i;
    while (j < n && pred(j)) ++j;
    out.push_back({i, j});
    i = j;
  }
  return out;
}

TEST(TextureGen, EveryKindIsDeterministicAndSized) {
  for (auto kind : {TextureDesc::Kind::Checker, TextureDesc::Kind::EyeChart, TextureDesc::Kind::Page,
                    TextureDesc::Kind::Bricks, TextureDesc::Kind::Road, TextureDesc::Kind::Windows,
                    TextureDesc::Kind::Sky, TextureDesc::Kind::Sign}) {
    TextureDesc d = desc(kind, 320, 400, Vec3(0.8, 0.7, 0.6), Vec3(0.05, 0.1, 0.2));
    const TextureImage a = generateTexture(d), b = generateTexture(d);
    EXPECT_EQ(a.width, 320);
    EXPECT_EQ(a.height, 400);
    EXPECT_EQ(a.rgb.size(), 320u * 400u * 3u);
    EXPECT_EQ(a.rgb, b.rgb) << nameOf(kind);
    maybeWrite(a, nameOf(kind));
  }
}

TEST(TextureGen, SeedChangesTheVariationOnly) {
  TextureDesc d = desc(TextureDesc::Kind::Page, 256, 256, Vec3(0.9), Vec3(0.0));
  d.rows = 12;
  const TextureImage a = generateTexture(d);
  d.seed = 7;
  const TextureImage b = generateTexture(d);
  EXPECT_NE(a.rgb, b.rgb);
}

TEST(TextureGen, RejectsWhatTheLoaderRejects) {
  EXPECT_THROW(generateTexture(desc(TextureDesc::Kind::Image, 64, 64, Vec3(1), Vec3(0))), Error);
  EXPECT_THROW(generateTexture(desc(TextureDesc::Kind::Checker, 2048, 64, Vec3(1), Vec3(0))), Error);
  TextureDesc chart = desc(TextureDesc::Kind::EyeChart, 64, 64, Vec3(1), Vec3(0));
  chart.rows = eyeChartMaxRows(64, 64) + 1;
  EXPECT_THROW(generateTexture(chart), Error);
  EXPECT_GE(eyeChartMaxRows(512, 512), 8);  // the loader's default rows fit its default resolution
}

TEST(TextureGen, CheckerAlternates) {
  TextureDesc d = desc(TextureDesc::Kind::Checker, 100, 60, Vec3(0.9), Vec3(0.1));
  d.squares_u = 5;
  d.squares_v = 3;
  const TextureImage img = generateTexture(d);
  const Rgb a = code(d.color_a), b = code(d.color_b);
  EXPECT_EQ(pixel(img, 0, 0), a);  // top-left square is colour a
  // Along any row and column the colour changes exactly squares - 1 times, alternating a and b.
  for (int y = 0; y < img.height; y += 7) {
    const auto row_runs = runs(img.width, [&](int x) { return pixel(img, x, y) == a; });
    const auto b_runs = runs(img.width, [&](int x) { return pixel(img, x, y) == b; });
    EXPECT_EQ(row_runs.size() + b_runs.size(), 5u) << "row " << y;
    for (const auto& r : row_runs) EXPECT_EQ(r.second - r.first, 20);
  }
  for (int x = 0; x < img.width; x += 9) {
    const auto col_runs = runs(img.height, [&](int y) { return pixel(img, x, y) == a; });
    const auto b_runs = runs(img.height, [&](int y) { return pixel(img, x, y) == b; });
    EXPECT_EQ(col_runs.size() + b_runs.size(), 3u) << "column " << x;
  }
}

TEST(TextureGen, EyeChartRowsShrinkAndHoldTumblingEs) {
  TextureDesc d = desc(TextureDesc::Kind::EyeChart, 512, 768, Vec3(1.0), Vec3(0.0));
  d.rows = 8;
  const TextureImage img = generateTexture(d);
  const Rgb white{255, 255, 255}, black{0, 0, 0};
  // Only black and white.
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const Rgb p = pixel(img, x, y);
      ASSERT_TRUE(p == white || p == black) << x << "," << y;
    }
  const auto dark_row = [&](int y) {
    for (int x = 0; x < img.width; ++x)
      if (pixel(img, x, y) == black) return true;
    return false;
  };
  const auto bands = runs(img.height, dark_row);
  ASSERT_EQ(bands.size(), 8u);
  int previous_height = img.height;
  for (size_t r = 0; r < bands.size(); ++r) {
    const int top = bands[r].first, height = bands[r].second - bands[r].first;
    // Each band is one optotype size: 5 strokes tall, strictly smaller than the band above.
    EXPECT_EQ(height % 5, 0) << "row " << r;
    EXPECT_LT(height, previous_height) << "row " << r;
    previous_height = height;
    const int stroke = height / 5;
    // Optotypes are separated by blank columns; row r holds r + 1 of them (up to 8).
    const auto glyphs = runs(img.width, [&](int x) {
      for (int y = top; y < bands[r].second; ++y)
        if (pixel(img, x, y) == black) return true;
      return false;
    });
    EXPECT_EQ(glyphs.size(), std::min<size_t>(r + 1, kEyeChartMaxLetters)) << "row " << r;
    for (const auto& g : glyphs) {
      EXPECT_EQ(g.second - g.first, height) << "optotypes are square, row " << r;
      // A tumbling E covers 17 of its 25 stroke cells, whatever its orientation.
      int dark = 0;
      for (int y = top; y < bands[r].second; ++y)
        for (int x = g.first; x < g.second; ++x) dark += pixel(img, x, y) == black;
      EXPECT_EQ(dark, 17 * stroke * stroke) << "row " << r;
    }
  }
  // Sizes fall by about 0.1 logMAR per row (integer strokes round it).
  const double first = bands[0].second - bands[0].first, third = bands[2].second - bands[2].first;
  EXPECT_NEAR(third / first, kEyeChartRowRatio * kEyeChartRowRatio, 0.1);
}

TEST(TextureGen, PageHasTheRequestedLinesInsideTheMargins) {
  TextureDesc d = desc(TextureDesc::Kind::Page, 400, 560, Vec3(0.85, 0.82, 0.75), Vec3(0.02));
  d.rows = 30;
  const TextureImage img = generateTexture(d);
  const Rgb ink = code(d.color_b);
  const auto ink_in_row = [&](int y) {
    for (int x = 0; x < img.width; ++x)
      if (pixel(img, x, y) == ink) return true;
    return false;
  };
  EXPECT_EQ(runs(img.height, ink_in_row).size(), 30u);
  const int margin_x = static_cast<int>(0.08 * img.width) - 1, margin_y = static_cast<int>(0.08 * img.height) - 1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (x >= margin_x && x < img.width - margin_x && y >= margin_y && y < img.height - margin_y) continue;
      ASSERT_NE(pixel(img, x, y), ink) << "ink in the margin at " << x << "," << y;
    }
  EXPECT_THROW(generateTexture([&] {
                 TextureDesc t = d;
                 t.rows = pageMaxLines(t.height) + 1;
                 return t;
               }()),
               Error);
}

TEST(TextureGen, BricksAreARunningBond) {
  TextureDesc d = desc(TextureDesc::Kind::Bricks, 256, 256, Vec3(0.45, 0.12, 0.07), Vec3(0.55, 0.53, 0.5));
  d.rows = 8;
  const TextureImage img = generateTexture(d);
  const Rgb mortar = code(d.color_b);
  const int course = img.height / d.rows;
  // The first row of every course is a bed joint: all mortar.
  for (int c = 0; c < d.rows; ++c)
    for (int x = 0; x < img.width; ++x) ASSERT_EQ(pixel(img, x, c * course), mortar) << "course " << c;
  // Head joints (mortar columns) in the middle of a course; odd courses shift them by half a brick.
  const auto heads = [&](int c) {
    const int y = c * course + course / 2;
    std::vector<int> starts;
    for (const auto& r : runs(img.width, [&](int x) { return pixel(img, x, y) == mortar; })) starts.push_back(r.first);
    return starts;
  };
  const std::vector<int> even = heads(0), odd = heads(1);
  ASSERT_GE(even.size(), 2u);
  ASSERT_EQ(even.size(), odd.size());
  const int brick = img.width / static_cast<int>(even.size());
  std::set<int> shifted;
  for (int x : even) shifted.insert((x + brick / 2) % img.width);  // where the odd course's joints should be
  EXPECT_EQ(std::set<int>(odd.begin(), odd.end()), shifted);
  EXPECT_EQ(heads(2), even);
  // Bricks are red (the brick colour dominates its red channel), never mortar grey.
  const Rgb p = pixel(img, brick / 2 + 3, course / 2);
  EXPECT_GT(p[0], p[1] + 40);
}

TEST(TextureGen, RoadHasSolidEdgeLinesAndDashedLaneDividers) {
  TextureDesc d = desc(TextureDesc::Kind::Road, 400, 300, Vec3(0.045), Vec3(0.8, 0.8, 0.75));
  d.lanes = 3;
  const TextureImage img = generateTexture(d);
  // Markings are bright, asphalt dark: split at mid-grey.
  const auto marking = [&](int x, int y) { return luma(pixel(img, x, y)) > 128; };
  std::vector<double> fraction(img.width, 0);
  for (int x = 0; x < img.width; ++x) {
    int n = 0;
    for (int y = 0; y < img.height; ++y) n += marking(x, y);
    fraction[x] = static_cast<double>(n) / img.height;
  }
  const auto lines = runs(img.width, [&](int x) { return fraction[x] > 0; });
  ASSERT_EQ(lines.size(), 4u);  // two edge lines, lanes - 1 = 2 dividers
  // Edge lines: marked on every row, placed symmetrically.
  EXPECT_DOUBLE_EQ(fraction[lines.front().first], 1.0);
  EXPECT_DOUBLE_EQ(fraction[lines.back().first], 1.0);
  EXPECT_EQ(lines.front().first, img.width - lines.back().second);
  // Dividers: dashed, 40 % of the length, at equal lane widths between the edge lines.
  constexpr double kDutyTol = 0.01;  // one row in 300, from integer dash boundaries
  for (size_t i = 1; i + 1 < lines.size(); ++i) EXPECT_NEAR(fraction[lines[i].first], 0.4, kDutyTol);
  const double lane1 = lines[1].first - lines[0].first, lane2 = lines[2].first - lines[1].first,
               lane3 = lines[3].first - lines[2].first;
  EXPECT_LE(std::abs(lane1 - lane2), 1.0);
  EXPECT_LE(std::abs(lane2 - lane3), 1.0);
  // Every row crosses the two edge lines, and the dashes come in two runs per repeat.
  const auto dash_rows = runs(img.height, [&](int y) { return marking(lines[1].first, y); });
  EXPECT_EQ(dash_rows.size(), 2u);
}

TEST(TextureGen, WindowsFormTheRequestedGrid) {
  TextureDesc d = desc(TextureDesc::Kind::Windows, 480, 400, Vec3(0.6, 0.45, 0.32), Vec3(0.05, 0.08, 0.12));
  d.columns = 6;
  d.floors = 5;
  const TextureImage img = generateTexture(d);
  const Rgb wall = code(d.color_a);
  const double cell_w = 480.0 / 6, cell_h = 400.0 / 5;
  for (int f = 0; f < d.floors; ++f) {
    const int y = static_cast<int>((f + 0.55) * cell_h);  // through the glass below any blind
    EXPECT_EQ(runs(img.width, [&](int x) { return pixel(img, x, y) != wall; }).size(), 6u) << "floor " << f;
    for (int c = 0; c < d.columns; ++c) {
      const int x = static_cast<int>((c + 0.5) * cell_w);
      EXPECT_LT(luma(pixel(img, x, y)), luma(wall)) << "glass darker than the wall";
      EXPECT_EQ(pixel(img, static_cast<int>(c * cell_w) + 2, static_cast<int>(f * cell_h) + 2), wall);
    }
  }
  const int x = static_cast<int>(0.5 * cell_w);
  EXPECT_EQ(runs(img.height, [&](int y) { return pixel(img, x, y) != wall; }).size(), 5u);
}

TEST(TextureGen, SkyIsAVerticalGradientFromZenithToHorizon) {
  const TextureDesc d = desc(TextureDesc::Kind::Sky, 32, 128, Vec3(0.75, 0.85, 1.0), Vec3(0.15, 0.3, 0.75));
  const TextureImage img = generateTexture(d);
  EXPECT_EQ(pixel(img, 0, 0), code(d.color_b));
  EXPECT_EQ(pixel(img, 0, img.height - 1), code(d.color_a));
  for (int y = 0; y < img.height; ++y) {
    for (int x = 1; x < img.width; ++x) ASSERT_EQ(pixel(img, x, y), pixel(img, 0, y));
    if (y > 0) {
      for (int k = 0; k < 3; ++k) ASSERT_GE(pixel(img, 0, y)[k], pixel(img, 0, y - 1)[k]) << "row " << y;
    }
  }
}

TEST(TextureGen, SignHasBorderAndSymmetricSymbol) {
  for (const char* symbol : {"arrow", "bar", "ring", "cross"}) {
    TextureDesc d = desc(TextureDesc::Kind::Sign, 200, 200, Vec3(0.01, 0.1, 0.5), Vec3(0.9));
    d.symbol = symbol;
    const TextureImage img = generateTexture(d);
    const Rgb panel = code(d.color_a), mark = code(d.color_b);
    EXPECT_EQ(pixel(img, 0, 0), panel) << symbol;                  // outer rim
    EXPECT_EQ(pixel(img, 12, 100), mark) << symbol;                // border line, 4 % to 9 % in
    EXPECT_EQ(pixel(img, 30, 30), panel) << symbol;                // inside the border, away from the symbol
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) ASSERT_EQ(pixel(img, x, y), pixel(img, img.width - 1 - x, y)) << symbol;
  }
  // The arrow points up: its head is wide near the middle and narrows towards the top.
  TextureDesc d = desc(TextureDesc::Kind::Sign, 200, 200, Vec3(0.01, 0.1, 0.5), Vec3(0.9));
  const TextureImage img = generateTexture(d);
  const Rgb mark = code(d.color_b);
  const auto width_at = [&](int y) {
    int n = 0;
    for (int x = 30; x < 170; ++x) n += pixel(img, x, y) == mark;
    return n;
  };
  // Symbol box: 100 px about the centre; head from row 55 (apex) to 95, shaft from 95 to 145.
  EXPECT_GT(width_at(93), width_at(70));
  EXPECT_GT(width_at(70), width_at(60));
  EXPECT_GT(width_at(93), width_at(130));  // the shaft is narrower than the head
  EXPECT_GT(width_at(130), 0);
}

}  // namespace
}  // namespace pvrr

#include "pvrr/scene/texture_gen.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "pvrr/base/error.h"
#include "pvrr/base/image.h"

namespace pvrr {
namespace {

using Rgb8 = std::array<uint8_t, 3>;

// splitmix64 (Steele, Lea, Flood 2014): a fixed, portable sequence (std distributions are not portable).
struct Rng {
  uint64_t state;
  explicit Rng(uint32_t seed, uint64_t stream) : state(seed * 0x9E3779B97F4A7C15ull ^ stream) {}
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int below(int n) { return static_cast<int>(next() % static_cast<uint64_t>(n)); }
};

Rgb8 encode(const Vec3& linear) {
  return {linearToSrgb8(linear.x), linearToSrgb8(linear.y), linearToSrgb8(linear.z)};
}

class Canvas {
 public:
  Canvas(int w, int h) {
    img_.width = w;
    img_.height = h;
    img_.rgb.assign(static_cast<size_t>(w) * h * 3, 0);
  }
  int w() const { return img_.width; }
  int h() const { return img_.height; }
  void set(int x, int y, const Rgb8& c) {
    uint8_t* p = &img_.rgb[(static_cast<size_t>(y) * img_.width + x) * 3];
    p[0] = c[0];
    p[1] = c[1];
    p[2] = c[2];
  }
  void fill(const Rgb8& c) { rect(0, 0, w(), h(), c); }
  // Half-open pixel rectangle [x0, x1) x [y0, y1), clipped.
  void rect(int x0, int y0, int x1, int y1, const Rgb8& c) {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, w());
    y1 = std::min(y1, h());
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) set(x, y, c);
  }
  TextureImage take() { return std::move(img_); }

 private:
  TextureImage img_;
};

int roundi(double v) { return static_cast<int>(std::lround(v)); }

TextureImage checker(const TextureDesc& d) {
  Canvas c(d.width, d.height);
  const Rgb8 a = encode(d.color_a), b = encode(d.color_b);
  for (int y = 0; y < d.height; ++y) {
    const int cy = static_cast<int>(static_cast<int64_t>(y) * d.squares_v / d.height);
    for (int x = 0; x < d.width; ++x) {
      const int cx = static_cast<int>(static_cast<int64_t>(x) * d.squares_u / d.width);
      c.set(x, y, ((cx + cy) % 2 == 0) ? a : b);
    }
  }
  return c.take();
}

// Eye chart (tumbling E, Snellen/ETDRS-like): each optotype is 5 x 5 strokes; row r is one stroke size,
// sizes fall by kEyeChartRowRatio per row (integer strokes, strictly decreasing); rows are separated by 3
// strokes of the row above; optotypes in a row by 5 strokes. Everything fits in the central 90 % of the image.
struct EyeChartRow {
  int stroke = 0, y0 = 0, x0 = 0, letters = 0;
};

bool eyeChartLayout(int width, int height, int rows, std::vector<EyeChartRow>* out) {
  const int usable_w = (9 * width) / 10, usable_h = (9 * height) / 10;
  for (int k = usable_h / 5; k >= rows && k >= 1; --k) {
    std::vector<int> s(rows);
    s[0] = k;
    for (int r = 1; r < rows; ++r) s[r] = std::min(roundi(k * std::pow(kEyeChartRowRatio, r)), s[r - 1] - 1);
    if (s.back() < 1 || 5 * k > usable_w) continue;
    int total = 0;
    for (int r = 0; r < rows; ++r) total += 5 * s[r] + (r + 1 < rows ? 3 * s[r] : 0);
    if (total > usable_h) continue;
    if (out) {
      out->clear();
      int y = (height - total) / 2;
      for (int r = 0; r < rows; ++r) {
        EyeChartRow row;
        row.stroke = s[r];
        row.y0 = y;
        row.letters = std::min({r + 1, kEyeChartMaxLetters, (usable_w + 5 * s[r]) / (10 * s[r])});
        row.x0 = (width - (10 * row.letters - 5) * s[r]) / 2;
        out->push_back(row);
        y += 8 * s[r];
      }
    }
    return true;
  }
  return false;
}

// A tumbling E in a 5 x 5 cell grid: the spine on one side, three arms; `open` is the side the arms point
// to: 0 right (the letter E), 1 left, 2 up, 3 down.
bool eCell(int cx, int cy, int open) {
  switch (open) {
    case 0: return cx == 0 || cy % 2 == 0;
    case 1: return cx == 4 || cy % 2 == 0;
    case 2: return cy == 4 || cx % 2 == 0;
    default: return cy == 0 || cx % 2 == 0;
  }
}

TextureImage eyeChart(const TextureDesc& d) {
  std::vector<EyeChartRow> rows;
  if (!eyeChartLayout(d.width, d.height, d.rows, &rows))
    throw Error("eye-chart texture: " + std::to_string(d.rows) + " rows do not fit in " +
                std::to_string(d.width) + " x " + std::to_string(d.height) + " pixels");
  Canvas c(d.width, d.height);
  c.fill(encode(d.color_a));
  const Rgb8 ink = encode(d.color_b);
  Rng rng(d.seed, 1);
  for (const EyeChartRow& row : rows) {
    for (int i = 0; i < row.letters; ++i) {
      const int open = rng.below(4);
      const int lx = row.x0 + i * 10 * row.stroke;
      for (int cy = 0; cy < 5; ++cy)
        for (int cx = 0; cx < 5; ++cx)
          if (eCell(cx, cy, open))
            c.rect(lx + cx * row.stroke, row.y0 + cy * row.stroke, lx + (cx + 1) * row.stroke,
                   row.y0 + (cy + 1) * row.stroke, ink);
    }
  }
  return c.take();
}

// A printed page: 8 % margins, `rows` lines of pseudo-glyphs (stroked boxes, stems, arches) with
// x-height, ascenders and descenders, justified lines, paragraphs ending in a short line.
TextureImage page(const TextureDesc& d) {
  if (d.rows > pageMaxLines(d.height))
    throw Error("page texture: " + std::to_string(d.rows) + " lines do not fit in " + std::to_string(d.height) +
                " pixels (at most " + std::to_string(pageMaxLines(d.height)) + ")");
  Canvas c(d.width, d.height);
  c.fill(encode(d.color_a));
  const Rgb8 ink = encode(d.color_b);
  Rng rng(d.seed, 2);
  const int left = roundi(0.08 * d.width), right = d.width - left;
  const double top = 0.08 * d.height;
  const double pitch = (d.height - 2 * top) / d.rows;
  const int stroke = std::max(1, roundi(0.08 * pitch));
  int lines_left_in_paragraph = 4 + rng.below(6);
  bool paragraph_start = true;
  for (int line = 0; line < d.rows; ++line) {
    const double line_top = top + line * pitch;
    const int base = static_cast<int>(line_top + 0.7 * pitch);
    const int x_top = static_cast<int>(line_top + 0.32 * pitch);   // x-height 0.38 pitch
    const int asc_top = static_cast<int>(line_top + 0.1 * pitch);  // ascenders 0.6 pitch
    const int desc_bot = static_cast<int>(line_top + 0.85 * pitch);
    const bool last_of_paragraph = (--lines_left_in_paragraph == 0) || line + 1 == d.rows;
    const int x_end = last_of_paragraph ? left + roundi(rng.uniform(0.3, 0.8) * (right - left)) : right;
    int x = left + (paragraph_start ? roundi(1.5 * pitch) : 0);
    while (x < x_end) {
      const int glyphs = 2 + rng.below(8);
      for (int g = 0; g < glyphs && x < x_end; ++g) {
        const int w = std::max(3 * stroke, roundi(pitch * rng.uniform(0.28, 0.55)));
        if (x + w > x_end) {
          x = x_end;
          break;
        }
        const double kind = rng.uniform();
        int y0 = x_top, y1 = base;
        if (kind < 0.25) y0 = asc_top;          // ascender (b, d, h, l, k)
        else if (kind < 0.35) y1 = desc_bot;    // descender (g, p, q, y)
        switch (rng.below(4)) {
          case 0:  // o-like: a stroked box
            c.rect(x, y0, x + w, y0 + stroke, ink);
            c.rect(x, y1 - stroke, x + w, y1, ink);
            c.rect(x, y0, x + stroke, y1, ink);
            c.rect(x + w - stroke, y0, x + w, y1, ink);
            break;
          case 1:  // n-like: two stems and a top bar
            c.rect(x, y0, x + w, y0 + stroke, ink);
            c.rect(x, y0, x + stroke, y1, ink);
            c.rect(x + w - stroke, y0, x + w, y1, ink);
            break;
          case 2:  // e-like: box open at the lower right, middle bar
            c.rect(x, y0, x + w, y0 + stroke, ink);
            c.rect(x, (y0 + y1) / 2, x + w, (y0 + y1) / 2 + stroke, ink);
            c.rect(x, y1 - stroke, x + w, y1, ink);
            c.rect(x, y0, x + stroke, y1, ink);
            c.rect(x + w - stroke, y0, x + w, (y0 + y1) / 2 + stroke, ink);
            break;
          default:  // l-like: a stem with a foot
            c.rect(x + w / 2 - stroke / 2, y0, x + w / 2 - stroke / 2 + stroke, y1, ink);
            c.rect(x, y1 - stroke, x + w, y1, ink);
            break;
        }
        x += w + std::max(1, roundi(0.1 * pitch));
      }
      x += roundi(0.35 * pitch);
    }
    paragraph_start = last_of_paragraph;
    if (last_of_paragraph) lines_left_in_paragraph = 4 + rng.below(6);
  }
  return c.take();
}

// Running-bond bricks: `rows` courses; mortar joints at the top of each course and at the start of each
// brick, odd courses shifted by half a brick; tiles in both directions for an even number of courses.
TextureImage bricks(const TextureDesc& d) {
  Canvas c(d.width, d.height);
  const Rgb8 mortar = encode(d.color_b);
  Rng rng(d.seed, 3);
  const double course_h = static_cast<double>(d.height) / d.rows;
  const int per_course = std::max(2, roundi(d.width / (2.1 * course_h)));
  const int joint = std::max(1, roundi(0.12 * course_h));
  const int half = d.width / (2 * per_course);
  std::vector<double> tint(static_cast<size_t>(d.rows) * per_course);
  for (double& t : tint) t = rng.uniform(0.8, 1.15);
  for (int y = 0; y < d.height; ++y) {
    const int course = static_cast<int>(static_cast<int64_t>(y) * d.rows / d.height);
    const int course_y0 = static_cast<int>((static_cast<int64_t>(course) * d.height + d.rows - 1) / d.rows);
    for (int x = 0; x < d.width; ++x) {
      const int xs = (course % 2 == 1) ? (x + half) % d.width : x;
      const int brick = static_cast<int>(static_cast<int64_t>(xs) * per_course / d.width);
      const int brick_x0 = static_cast<int>((static_cast<int64_t>(brick) * d.width + per_course - 1) / per_course);
      if (y - course_y0 < joint || xs - brick_x0 < joint) {
        c.set(x, y, mortar);
      } else {
        const double t = tint[static_cast<size_t>(course) * per_course + brick] * rng.uniform(0.94, 1.06);
        c.set(x, y, encode(glm::clamp(d.color_a * t, 0.0, 1.0)));
      }
    }
  }
  return c.take();
}

// Road: u (image x) across the carriageway, v (image y) along it. Solid edge lines 3 % in from each side,
// dashed lane dividers between them (two dashes per repeat, 40 % duty), asphalt with grain elsewhere.
TextureImage road(const TextureDesc& d) {
  Canvas c(d.width, d.height);
  Rng rng(d.seed, 4);
  const int inset = roundi(0.03 * d.width), line_w = std::max(1, roundi(0.025 * d.width));
  const double left_c = inset + 0.5 * line_w, right_c = d.width - inset - 0.5 * line_w;
  std::vector<int> column(d.width, 0);  // 0 asphalt, 1 solid line, 2 dashed line
  for (int x = inset; x < inset + line_w; ++x) column[x] = 1;
  for (int x = d.width - inset - line_w; x < d.width - inset; ++x) column[x] = 1;
  for (int i = 1; i < d.lanes; ++i) {
    const int x0 = roundi(left_c + i * (right_c - left_c) / d.lanes - 0.5 * line_w);
    for (int x = std::max(0, x0); x < std::min(d.width, x0 + line_w); ++x) column[x] = 2;
  }
  for (int y = 0; y < d.height; ++y) {
    const bool dash = (2 * y) % d.height < (4 * d.height) / 10;
    for (int x = 0; x < d.width; ++x) {
      const bool marking = column[x] == 1 || (column[x] == 2 && dash);
      const double grain = marking ? rng.uniform(0.93, 1.0) : rng.uniform(0.75, 1.25);
      c.set(x, y, encode(glm::clamp((marking ? d.color_b : d.color_a) * grain, 0.0, 1.0)));
    }
  }
  return c.take();
}

// Facade: `columns` x `floors` cells; each holds a window (the middle half of the cell's width, 20 % to
// 75 % of its height) with a light frame, glass of varying brightness, and sometimes a blind in its top
// third. Wall elsewhere, exactly color_a.
TextureImage windows(const TextureDesc& d) {
  Canvas c(d.width, d.height);
  c.fill(encode(d.color_a));
  Rng rng(d.seed, 5);
  const Rgb8 frame = encode(Vec3(0.75, 0.75, 0.72));
  const Rgb8 blind = encode(Vec3(0.62, 0.58, 0.5));
  for (int f = 0; f < d.floors; ++f) {
    for (int col = 0; col < d.columns; ++col) {
      const double cx0 = static_cast<double>(col) * d.width / d.columns;
      const double cy0 = static_cast<double>(f) * d.height / d.floors;
      const double cw = static_cast<double>(d.width) / d.columns, ch = static_cast<double>(d.height) / d.floors;
      const int x0 = roundi(cx0 + 0.25 * cw), x1 = roundi(cx0 + 0.75 * cw);
      const int y0 = roundi(cy0 + 0.2 * ch), y1 = roundi(cy0 + 0.75 * ch);
      const int fw = std::max(1, roundi(0.06 * std::min(x1 - x0, y1 - y0)));
      c.rect(x0, y0, x1, y1, frame);
      c.rect(x0 + fw, y0 + fw, x1 - fw, y1 - fw, encode(glm::clamp(d.color_b * rng.uniform(0.7, 1.4), 0.0, 1.0)));
      if (rng.uniform() < 0.25) c.rect(x0 + fw, y0 + fw, x1 - fw, y0 + fw + (y1 - y0 - 2 * fw) / 3, blind);
    }
  }
  return c.take();
}

// Sky: zenith (color_b) at the top row to horizon (color_a) at the bottom, mixed in linear light with
// t^1.5 (the sky brightens quickly near the horizon).
TextureImage sky(const TextureDesc& d) {
  Canvas c(d.width, d.height);
  for (int y = 0; y < d.height; ++y) {
    const double t = d.height > 1 ? static_cast<double>(y) / (d.height - 1) : 1.0;
    const Rgb8 col = encode(glm::mix(d.color_b, d.color_a, std::pow(t, 1.5)));
    for (int x = 0; x < d.width; ++x) c.set(x, y, col);
  }
  return c.take();
}

// Street sign: panel colour everywhere, a border line (color_b) 4 % to 9 % of the smaller side in from the
// edge, and a symbol in color_b centred in a box half the smaller side. Evaluated at pixel centres about
// the image centre, so every symbol is mirror-symmetric left to right.
bool signSymbol(const std::string& symbol, double x, double y, double s) {
  // x right, y down, both in units of the symbol box side s, origin at the centre.
  x /= s;
  y /= s;
  const double ax = std::abs(x);
  if (symbol == "bar") return ax <= 0.4 && std::abs(y) <= 0.1;
  if (symbol == "cross") return (ax <= 0.4 && std::abs(y) <= 0.1) || (ax <= 0.1 && std::abs(y) <= 0.4);
  if (symbol == "ring") {
    const double r = std::sqrt(x * x + y * y);
    return r <= 0.45 && r >= 0.3;
  }
  // arrow pointing up: shaft and a triangular head with its apex at y = -0.45
  if (ax <= 0.08 && y >= -0.05 && y <= 0.45) return true;
  return y >= -0.45 && y <= -0.05 && ax <= 0.35 * (y + 0.45) / 0.4;
}

TextureImage sign(const TextureDesc& d) {
  if (d.symbol != "arrow" && d.symbol != "bar" && d.symbol != "ring" && d.symbol != "cross")
    throw Error("sign texture: unknown symbol \"" + d.symbol + "\" (arrow, bar, ring or cross)");
  Canvas c(d.width, d.height);
  const Rgb8 panel = encode(d.color_a), mark = encode(d.color_b);
  const int m = std::min(d.width, d.height);
  const int rim = roundi(0.04 * m), border = std::max(1, roundi(0.05 * m));
  for (int y = 0; y < d.height; ++y) {
    for (int x = 0; x < d.width; ++x) {
      const int edge = std::min({x, y, d.width - 1 - x, d.height - 1 - y});
      const bool on_border = edge >= rim && edge < rim + border;
      const bool on_symbol = signSymbol(d.symbol, x + 0.5 - 0.5 * d.width, y + 0.5 - 0.5 * d.height, 0.5 * m);
      c.set(x, y, (on_border || on_symbol) ? mark : panel);
    }
  }
  return c.take();
}

}  // namespace

int eyeChartMaxRows(int width, int height) {
  for (int rows = 12; rows >= 1; --rows)
    if (eyeChartLayout(width, height, rows, nullptr)) return rows;
  return 0;
}

int pageMaxLines(int height) { return (84 * height) / 1000; }

TextureImage generateTexture(const TextureDesc& d) {
  if (d.kind == TextureDesc::Kind::Image)
    throw Error("texture \"" + d.image_path + "\": an image texture is read from its file, not generated");
  if (d.width < 8 || d.width > 1024 || d.height < 8 || d.height > 1024)
    throw Error(std::string(nameOf(d.kind)) + " texture: size " + std::to_string(d.width) + " x " +
                std::to_string(d.height) + " outside [8, 1024]");
  const auto positive = [&](int v, const char* what) {
    if (v < 1) throw Error(std::string(nameOf(d.kind)) + " texture: " + what + " must be >= 1");
  };
  switch (d.kind) {
    case TextureDesc::Kind::Checker:
      positive(d.squares_u, "squares");
      positive(d.squares_v, "squares");
      return checker(d);
    case TextureDesc::Kind::EyeChart: positive(d.rows, "rows"); return eyeChart(d);
    case TextureDesc::Kind::Page: positive(d.rows, "lines"); return page(d);
    case TextureDesc::Kind::Bricks: positive(d.rows, "courses"); return bricks(d);
    case TextureDesc::Kind::Road: positive(d.lanes, "lanes"); return road(d);
    case TextureDesc::Kind::Windows:
      positive(d.columns, "columns");
      positive(d.floors, "floors");
      return windows(d);
    case TextureDesc::Kind::Sky: return sky(d);
    case TextureDesc::Kind::Sign: return sign(d);
    case TextureDesc::Kind::Image: break;
  }
  PVRR_CHECK(false, << "unhandled texture kind " << static_cast<int>(d.kind));
  return {};
}

}  // namespace pvrr

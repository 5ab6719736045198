// Pictures as primitives (rectangles, filled polygons, polylines, text), each drawn twice: rasterised to PNG (text by
// VTK's FreeType renderer, no GL) and written as SVG. The plots of pvrr lensmap and pvrr fov.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr::app {

// One picture as primitives, drawn twice: rasterised to PNG and written as SVG. Pixel coordinates, y down.
struct Rgb {
  double r = 0, g = 0, b = 0;
};
struct Rect {
  double x0, y0, x1, y1;
  Rgb c;
};
struct Line {
  std::vector<Vec2> pts;
  Rgb c;
  double width = 1;
  bool dashed = false;
};
struct Text {
  double x, y;  // baseline point
  std::string s;
  double size = 12;
  int anchor = 0;  // 0 start, 1 middle, 2 end
  Rgb c;
  bool halo = false;  // a white box behind (iso-line labels)
};
// A filled polygon (even-odd), drawn after the rectangles and before the lines; `alpha` its opacity.
struct Poly {
  std::vector<Vec2> pts;
  Rgb c;
  double alpha = 1;
};
struct Sketch {
  int width = 760, height = 640;
  std::vector<Rect> rects;
  std::vector<Poly> polys;
  std::vector<Line> lines;
  std::vector<Text> texts;
};

inline const Rgb kBlack{0, 0, 0}, kWhite{1, 1, 1}, kGrey{0.82, 0.82, 0.82}, kDark{0.25, 0.25, 0.25};

std::string hex(const Rgb& c);
std::string svg(const Sketch& k);
void writePng(const std::string& path, const Sketch& k);
// Writes DIR/FILE.png and DIR/FILE.svg; returns their paths.
std::vector<std::string> writeSketch(const std::string& dir, const std::string& file, const Sketch& k);

}  // namespace pvrr::app

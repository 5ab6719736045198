#include "app/sketch.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "pvrr/base/atomic_file.h"
#include "pvrr/base/format.h"
#include "pvrr/base/image.h"

namespace fs = std::filesystem;

namespace pvrr::app {

std::string hex(const Rgb& c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", int(std::lround(255 * std::clamp(c.r, 0.0, 1.0))),
                int(std::lround(255 * std::clamp(c.g, 0.0, 1.0))), int(std::lround(255 * std::clamp(c.b, 0.0, 1.0))));
  return buf;
}
namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char ch : s) {
    if (ch == '<')
      o += "&lt;";
    else if (ch == '>')
      o += "&gt;";
    else if (ch == '&')
      o += "&amp;";
    else
      o += ch;
  }
  return o;
}

}  // namespace

std::string svg(const Sketch& k) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << k.width << "\" height=\"" << k.height
    << "\" font-family=\"Arial, Helvetica, sans-serif\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const Rect& r : k.rects)
    o << "<rect x=\"" << r.x0 << "\" y=\"" << r.y0 << "\" width=\"" << (r.x1 - r.x0) << "\" height=\"" << (r.y1 - r.y0)
      << "\" fill=\"" << hex(r.c) << "\" shape-rendering=\"crispEdges\"/>\n";
  for (const Poly& q : k.polys) {
    o << "<polygon fill=\"" << hex(q.c) << "\" fill-opacity=\"" << q.alpha << "\" fill-rule=\"evenodd\" points=\"";
    for (const Vec2& p : q.pts) o << fmt("%.2f", p.x) << "," << fmt("%.2f", p.y) << " ";
    o << "\"/>\n";
  }
  for (const Line& l : k.lines) {
    o << "<polyline fill=\"none\" stroke=\"" << hex(l.c) << "\" stroke-width=\"" << l.width << "\""
      << (l.dashed ? " stroke-dasharray=\"4 3\"" : "") << " points=\"";
    for (const Vec2& p : l.pts) o << fmt("%.2f", p.x) << "," << fmt("%.2f", p.y) << " ";
    o << "\"/>\n";
  }
  for (const Text& t : k.texts) {
    if (t.halo) {
      const double w = 0.6 * t.size * double(t.s.size());
      const double x0 = t.anchor == 0 ? t.x : t.anchor == 1 ? t.x - w / 2 : t.x - w;
      o << "<rect x=\"" << x0 - 1 << "\" y=\"" << t.y - t.size << "\" width=\"" << w + 2 << "\" height=\""
        << t.size * 1.25 << "\" fill=\"white\" fill-opacity=\"0.8\"/>\n";
    }
    o << "<text x=\"" << t.x << "\" y=\"" << t.y << "\" font-size=\"" << t.size << "\" fill=\"" << hex(t.c)
      << "\" text-anchor=\""
      << (t.anchor == 0   ? "start"
          : t.anchor == 1 ? "middle"
                          : "end")
      << "\">" << esc(t.s) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

namespace {

// Raster: linear blending in sRGB-encoded values (fine for flat colours and thin lines).
struct Raster {
  int w, h;
  std::vector<double> px;  // rgb in [0, 1]
  Raster(int w_, int h_) : w(w_), h(h_), px(size_t(w_) * size_t(h_) * 3, 1.0) {}
  void blend(int x, int y, const Rgb& c, double a) {
    if (x < 0 || y < 0 || x >= w || y >= h || a <= 0) return;
    double* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 3];
    a = std::min(a, 1.0);
    p[0] += (c.r - p[0]) * a;
    p[1] += (c.g - p[1]) * a;
    p[2] += (c.b - p[2]) * a;
  }
  void rect(double x0, double y0, double x1, double y1, const Rgb& c, double a = 1) {
    for (int y = int(std::floor(y0)); y < int(std::ceil(y1)); ++y)
      for (int x = int(std::floor(x0)); x < int(std::ceil(x1)); ++x) {
        // Coverage of the pixel by the rectangle (edges antialiased).
        const double cx = std::min(x1, x + 1.0) - std::max(x0, double(x)),
                     cy = std::min(y1, y + 1.0) - std::max(y0, double(y));
        if (cx > 0 && cy > 0) blend(x, y, c, a * cx * cy);
      }
  }
  // Even-odd fill, 4 x 4 samples per pixel.
  void polygon(const std::vector<Vec2>& pts, const Rgb& c, double alpha) {
    if (pts.size() < 3) return;
    double y0 = kInf, y1 = -kInf;
    for (const Vec2& p : pts) {
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
    std::vector<double> cover(size_t(w), 0.0);
    for (int y = std::max(0, int(std::floor(y0))); y < std::min(h, int(std::ceil(y1)) + 1); ++y) {
      std::fill(cover.begin(), cover.end(), 0.0);
      for (int sy = 0; sy < 4; ++sy) {
        const double yy = y + (sy + 0.5) / 4;
        std::vector<double> xs;
        for (size_t i = 0, j = pts.size() - 1; i < pts.size(); j = i++) {
          const Vec2 &a = pts[i], &b = pts[j];
          if ((a.y > yy) != (b.y > yy)) xs.push_back(a.x + (yy - a.y) / (b.y - a.y) * (b.x - a.x));
        }
        std::sort(xs.begin(), xs.end());
        for (size_t i = 0; i + 1 < xs.size(); i += 2)
          for (int sx = 0; sx < 4 * w; ++sx) {
            const double xx = (sx + 0.5) / 4;
            if (xx >= xs[i] && xx < xs[i + 1]) cover[size_t(sx / 4)] += 1.0 / 16;
          }
      }
      for (int x = 0; x < w; ++x)
        if (cover[size_t(x)] > 0) blend(x, y, c, alpha * cover[size_t(x)]);
    }
  }
  void segment(Vec2 a, Vec2 b, const Rgb& c, double width) {
    const double r = width / 2;
    const int x0 = int(std::floor(std::min(a.x, b.x) - r - 1)), x1 = int(std::ceil(std::max(a.x, b.x) + r + 1));
    const int y0 = int(std::floor(std::min(a.y, b.y) - r - 1)), y1 = int(std::ceil(std::max(a.y, b.y) + r + 1));
    const Vec2 d = b - a;
    const double len2 = glm::dot(d, d);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Vec2 p(x + 0.5, y + 0.5);
        const double t = len2 > 0 ? std::clamp(glm::dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
        const double dist = glm::length(p - (a + t * d));
        blend(x, y, c, std::clamp(r + 0.5 - dist, 0.0, 1.0));
      }
  }
  void text(const Text& t) {
    vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
    if (!tr) return;
    vtkNew<vtkTextProperty> tp;
    tp->SetFontFamilyToArial();
    tp->SetFontSize(int(std::lround(t.size)));
    tp->SetColor(t.c.r, t.c.g, t.c.b);
    vtkNew<vtkImageData> img;
    int dims[2] = {0, 0};
    if (!tr->RenderString(tp.GetPointer(), vtkStdString(t.s), img.GetPointer(), dims, 72)) return;
    int ext[6];
    img->GetExtent(ext);
    const double x0 = t.anchor == 0 ? t.x : t.anchor == 1 ? t.x - dims[0] / 2.0 : t.x - dims[0];
    const double top = t.y - 0.8 * dims[1];
    if (t.halo) rect(x0 - 2, top - 1, x0 + dims[0] + 2, top + dims[1] + 1, kWhite, 0.8);
    for (int y = 0; y < dims[1]; ++y)
      for (int x = 0; x < dims[0]; ++x) {
        const auto* p = static_cast<const unsigned char*>(img->GetScalarPointer(ext[0] + x, ext[2] + y, 0));
        if (!p) continue;
        blend(int(std::lround(x0)) + x, int(std::lround(top)) + dims[1] - 1 - y, t.c, p[3] / 255.0);
      }
  }
};

}  // namespace

void writePng(const std::string& path, const Sketch& k) {
  Raster r(k.width, k.height);
  // Filled areas snapped to whole pixels: abutting cells leave no seams.
  for (const Rect& q : k.rects) r.rect(std::round(q.x0), std::round(q.y0), std::round(q.x1), std::round(q.y1), q.c);
  for (const Poly& q : k.polys) r.polygon(q.pts, q.c, q.alpha);
  for (const Line& l : k.lines) {
    double run = 0;
    for (size_t i = 1; i < l.pts.size(); ++i) {
      if (!l.dashed) {
        r.segment(l.pts[i - 1], l.pts[i], l.c, l.width);
        continue;
      }
      // Dashes of 4 px on, 3 px off along the polyline.
      const Vec2 a = l.pts[i - 1], d = l.pts[i] - a;
      const double len = glm::length(d);
      for (double s = 0; s < len;) {
        const double phase = std::fmod(run + s, 7.0);
        const double step = std::min(len - s, phase < 4 ? 4 - phase : 7 - phase);
        if (phase < 4) r.segment(a + d * (s / len), a + d * ((s + step) / len), l.c, l.width);
        s += std::max(step, 1e-6);
      }
      run += len;
    }
  }
  for (const Text& t : k.texts) r.text(t);
  ImageRGB8 img(k.width, k.height);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x)
      for (int c = 0; c < 3; ++c)
        img.at(x, y)[c] = uint8_t(
            std::lround(255 * std::clamp(r.px[(size_t(y) * size_t(k.width) + size_t(x)) * 3 + size_t(c)], 0.0, 1.0)));
  writePngAtomic(path, img, MissingFolder::Create);
}

std::vector<std::string> writeSketch(const std::string& dir, const std::string& file, const Sketch& k) {
  const std::string base = (fs::path(dir) / file).string();
  writePng(base + ".png", k);
  writeFileAtomic(base + ".svg", svg(k));
  return {base + ".png", base + ".svg"};
}

}  // namespace pvrr::app

#include "app/lensmap_plot.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "app/sketch.h"
#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/base/image.h"

namespace fs = std::filesystem;

namespace pvrr::app {

namespace {

Rgb lerp(const Rgb& a, const Rgb& b, double t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}
Rgb ramp(const std::vector<Rgb>& stops, double t) {
  t = std::clamp(t, 0.0, 1.0) * double(stops.size() - 1);
  const size_t i = std::min(size_t(t), stops.size() - 2);
  return lerp(stops[i], stops[i + 1], t - double(i));
}
// The share of gazes the colour range spans; and the most iso-lines drawn before their spacing doubles.
constexpr double kColourQuantile = 0.98;
constexpr double kMaxIsoLines = 24;

// Cool-warm (diverging, for signed errors) and yellow-orange-red (sequential, for magnitudes).
const std::vector<Rgb> kDiverging = {
    {0.23, 0.30, 0.75}, {0.55, 0.69, 0.99}, {0.97, 0.97, 0.97}, {0.96, 0.60, 0.48}, {0.71, 0.02, 0.15}};
const std::vector<Rgb> kSequential = {
    {1.0, 1.0, 0.90}, {1.0, 0.85, 0.46}, {0.99, 0.55, 0.24}, {0.89, 0.10, 0.11}, {0.50, 0.0, 0.15}};

// The plot area and the axes common to the maps.
struct Frame {
  double left = 80, top = 80, size = 480;
  double lo = -40, hi = 40;  // data range on both axes
  Vec2 toPx(double x, double y) const {
    return Vec2(left + (x - lo) / (hi - lo) * size, top + (hi - y) / (hi - lo) * size);
  }
};

void axes(Sketch& k, const Frame& f, const std::string& title, const std::string& subtitle, const std::string& xlabel,
          const std::string& ylabel, double tick) {
  k.texts.push_back({k.width / 2.0, 26, title, 17, 1, kBlack});
  k.texts.push_back({k.width / 2.0, 46, subtitle, 12, 1, kDark});
  const double b = f.top + f.size;
  k.lines.push_back({{Vec2(f.left, f.top), Vec2(f.left + f.size, f.top), Vec2(f.left + f.size, b), Vec2(f.left, b),
                      Vec2(f.left, f.top)},
                     kBlack,
                     1});
  for (double v = std::ceil(f.lo / tick) * tick; v <= f.hi + 1e-9; v += tick) {
    const Vec2 px = f.toPx(v, v);
    k.lines.push_back({{Vec2(px.x, b), Vec2(px.x, b + 5)}, kBlack, 1});
    k.lines.push_back({{Vec2(f.left - 5, px.y), Vec2(f.left, px.y)}, kBlack, 1});
    k.texts.push_back({px.x, b + 18, fmt("%g", v), 11, 1, kBlack});
    k.texts.push_back({f.left - 8, px.y + 4, fmt("%g", v), 11, 2, kBlack});
  }
  k.texts.push_back({f.left + f.size / 2, b + 38, xlabel, 12, 1, kBlack});
  k.texts.push_back({f.left - 8, f.top - 8, ylabel, 12, 0, kBlack});
}

double niceStep(double span, int target) {
  const double raw = span / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

// A colour map of one LensmapPoint field over the gaze grid, with iso-lines and a colour bar.
struct FieldMap {
  std::string file, title, unit;
  std::vector<double> values;  // n x n, NaN where empty
  bool diverging = false;
  double step = 0.25;   // iso-line spacing
  bool arrows = false;  // prism: base directions
};

Sketch sketchField(const LensmapResult& r, const FieldMap& m, const std::string& empty_note) {
  const int n = r.options.grid;
  Sketch k;
  Frame f;
  f.lo = -r.options.gaze_max_deg;
  f.hi = r.options.gaze_max_deg;
  // The colour range holds 98 % of the gazes (a few extreme ones near the rim, e.g. beside a progressive
  // lens's corridor, would wash out the rest); beyond it the colours saturate and the bar says so.
  std::vector<double> finite;
  for (double v : m.values)
    if (std::isfinite(v)) finite.push_back(m.diverging ? std::abs(v) : v);
  std::sort(finite.begin(), finite.end());
  const double lo = finite.empty() ? 0 : finite.front();
  const double hi = finite.empty() ? 0 : finite[size_t(std::floor(kColourQuantile * double(finite.size() - 1)))];
  double cmin, cmax;
  if (m.diverging) {
    cmax = std::ceil(std::max(hi, m.step) / m.step - 1e-9) * m.step;
    cmin = -cmax;
  } else {
    cmin = std::min(0.0, std::floor(lo / m.step) * m.step);
    cmax = std::max(m.step, std::ceil(hi / m.step - 1e-9) * m.step);
  }
  const bool clipped = !finite.empty() && finite.back() > cmax;
  // Iso-lines every `step`, or every whole multiple of it when that would draw more than kMaxIsoLines.
  double step = m.step;
  {
    double vmin = kInf, vmax = -kInf;
    for (double v : m.values)
      if (std::isfinite(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    const double count = std::isfinite(vmin) ? (vmax - vmin) / m.step : 0;
    if (count > kMaxIsoLines) step = m.step * std::ceil(count / kMaxIsoLines);
  }
  const auto& stops = m.diverging ? kDiverging : kSequential;
  auto colour = [&](double v) { return ramp(stops, (v - cmin) / (cmax - cmin)); };
  // Cells.
  const double cell = f.size / n;
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const double v = m.values[size_t(iy) * size_t(n) + size_t(ix)];
      const double x0 = f.left + ix * cell, y0 = f.top + (n - 1 - iy) * cell;
      k.rects.push_back({x0, y0, x0 + cell, y0 + cell, std::isfinite(v) ? colour(v) : kGrey});
    }
  // Iso-lines (between cell centres) with labels, kept apart.
  auto gridPx = [&](const Vec2& g) { return Vec2(f.left + (g.x + 0.5) * cell, f.top + (n - 1 - g.y + 0.5) * cell); };
  std::vector<Vec2> labelled;
  double vmin = kInf, vmax = -kInf;
  for (double v : m.values)
    if (std::isfinite(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
  const std::vector<double> levels = isoLevels(vmin - step, vmax + step, step, 1000);
  for (double level : levels) {
    // A signed map's zero is its white; its line would trace rounding noise across a flat zone.
    if (m.diverging && std::abs(level) < 1e-12) continue;
    const auto segs = isoSegments(m.values, n, level);
    const bool major = std::abs(level) < 1e-12;
    for (const auto& s : segs)
      k.lines.push_back({{gridPx(s.first), gridPx(s.second)}, major ? kBlack : kDark, major ? 1.6 : 0.9});
    // Label the segment nearest to each of two anchors, unless another label is near.
    for (const Vec2 anchor : {Vec2(0.75, 0.7), Vec2(0.25, 0.3)}) {
      double best = kInf;
      Vec2 at(0);
      for (const auto& s : segs) {
        const Vec2 mid = gridPx(0.5 * (s.first + s.second));
        const double d = glm::length(mid - Vec2(f.left + anchor.x * f.size, f.top + anchor.y * f.size));
        if (d < best) {
          best = d;
          at = mid;
        }
      }
      if (!std::isfinite(best)) continue;
      bool clear = true;
      for (const Vec2& q : labelled) clear = clear && glm::length(q - at) > 40;
      if (!clear) continue;
      labelled.push_back(at);
      k.texts.push_back({at.x, at.y + 4, fmt("%g", level), 10, 1, kBlack, true});
    }
  }
  if (m.arrows) {
    // Base direction arrows on every k-th gaze: length proportional to the prism, the largest 0.9 cell-steps.
    const int every = std::max(1, n / 9);
    double pmax = 0;
    for (const LensmapPoint& p : r.points)
      if (p.valid) pmax = std::max(pmax, std::hypot(p.prism_h, p.prism_v));
    const double unit = pmax > 0 ? 0.9 * every * cell / pmax : 0;
    for (int iy = every / 2; iy < n; iy += every)
      for (int ix = every / 2; ix < n; ix += every) {
        const LensmapPoint& p = r.points[size_t(iy) * size_t(n) + size_t(ix)];
        if (!p.valid) continue;
        const Vec2 a = gridPx(Vec2(ix, iy)), d = Vec2(p.prism_h, -p.prism_v) * unit;
        if (glm::length(d) < 2) continue;
        const Vec2 b = a + d, u = glm::normalize(d), v(-u.y, u.x);
        k.lines.push_back({{a, b}, kBlack, 1.2});
        k.lines.push_back({{b - 5.0 * u + 3.0 * v, b, b - 5.0 * u - 3.0 * v}, kBlack, 1.2});
      }
  }
  axes(k, f, m.title, empty_note, "gaze_x (deg): towards the wearer's right", "gaze_y (deg): up",
       niceStep(2 * f.hi, 8));
  // Colour bar.
  const double bx = f.left + f.size + 40, bw = 22;
  const int steps = 240;
  for (int i = 0; i < steps; ++i) {
    const double t0 = double(i) / steps, t1 = double(i + 1) / steps;
    k.rects.push_back(
        {bx, f.top + f.size * (1 - t1), bx + bw, f.top + f.size * (1 - t0) + 0.5, ramp(stops, (t0 + t1) / 2)});
  }
  k.lines.push_back({{Vec2(bx, f.top), Vec2(bx + bw, f.top), Vec2(bx + bw, f.top + f.size), Vec2(bx, f.top + f.size),
                      Vec2(bx, f.top)},
                     kBlack,
                     1});
  const double tick = niceStep(cmax - cmin, 8);
  std::vector<double> ticks = isoLevels(cmin - tick / 2, cmax + tick / 2, tick, 1000);
  const size_t every = std::max<size_t>(1, (ticks.size() + 11) / 12);
  for (size_t i = 0; i < ticks.size(); i += every) {
    const double y = f.top + f.size * (1 - (ticks[i] - cmin) / (cmax - cmin));
    k.lines.push_back({{Vec2(bx + bw, y), Vec2(bx + bw + 5, y)}, kBlack, 1});
    k.texts.push_back({bx + bw + 8, y + 4, fmt("%g", ticks[i]), 11, 0, kBlack});
  }
  k.texts.push_back({bx + bw / 2, f.top - 8, m.unit, 12, 1, kBlack});
  if (clipped)
    k.texts.push_back({bx + bw / 2, f.top - 24, m.diverging ? "(ends: and beyond)" : "(top: and above)", 10, 1, kDark});
  k.texts.push_back({f.left + f.size / 2, f.top + f.size + 58,
                     "iso-lines every " + fmt("%g", step) + " " + m.unit + " (labelled); grey: no ray passes", 11, 1,
                     kDark});
  return k;
}

// Straight object lines as seen (solid) over the same lines without distortion (dashed), in gaze tangents.
Sketch sketchDistortion(const LensmapResult& r, const DistortionGrid& g) {
  Sketch k;
  Frame f;
  const double t = 100 * std::tan(radians(r.options.gaze_max_deg));
  f.lo = -t;
  f.hi = t;
  auto px = [&](const Vec2& v) { return f.toPx(100 * v.x, 100 * v.y); };
  auto inside = [&](const Vec2& v) { return std::abs(100 * v.x) <= t && std::abs(100 * v.y) <= t; };
  auto add = [&](const std::vector<std::vector<Vec2>>& lines, const Rgb& c, double w, bool dashed) {
    for (const auto& line : lines) {
      Line l{{}, c, w, dashed};
      for (const Vec2& v : line) {
        if (!inside(v)) {
          if (l.pts.size() > 1) k.lines.push_back(l);
          l.pts.clear();
          continue;
        }
        l.pts.push_back(px(v));
      }
      if (l.pts.size() > 1) k.lines.push_back(l);
    }
  };
  add(g.reference, Rgb{0.6, 0.6, 0.6}, 1, true);
  add(g.seen, Rgb{0.1, 0.2, 0.7}, 1.4, false);
  double worst = 0;
  for (const LensmapPoint& p : r.points)
    if (p.valid && std::isfinite(p.distortion_pct) && std::abs(p.distortion_pct) > std::abs(worst))
      worst = p.distortion_pct;
  axes(k, f, "Distortion: straight object lines as seen through the lens",
       "solid: as seen; dashed: without distortion (paraxial); largest " + fmt("%+.2f", worst) +
           " % (< 0 barrel, > 0 pincushion)",
       "100 tan(gaze_x): towards the wearer's right", "100 tan(gaze_y) / cos(gaze_x): up", niceStep(2 * t, 8));
  return k;
}

}  // namespace

std::vector<std::string> writeLensmapPlots(const std::string& dir, const LensmapResult& r,
                                           const DistortionGrid& distortion) {
  const size_t count = r.points.size();
  auto field = [&](double LensmapPoint::*member) {
    std::vector<double> v(count, std::nan(""));
    for (size_t i = 0; i < count; ++i)
      if (r.points[i].valid) v[i] = r.points[i].*member;
    return v;
  };
  const std::string rx = "against " + fmt("%+.2f", r.centre.sphere_d) + " / " + fmt("%+.2f", r.centre.cylinder_d) +
                         " x " + fmt("%.0f", r.centre.axis_deg) + " (straight ahead); rotation centre " +
                         fmt("%g", 1e3 * r.options.rotation_centre_m) + " mm; " + std::to_string(r.empty) + " of " +
                         std::to_string(count) + " gazes empty";
  std::vector<std::string> out;
  auto put = [&](const std::vector<std::string>& v) { out.insert(out.end(), v.begin(), v.end()); };
  put(writeSketch(dir, "power_error",
                  sketchField(r,
                              {"power_error", "Mean power error as worn: " + r.element, "D",
                               field(&LensmapPoint::power_error_d), true, 0.25, false},
                              rx)));
  put(writeSketch(dir, "cylinder",
                  sketchField(r,
                              {"cylinder", "Unwanted cylinder as worn: " + r.element, "D",
                               field(&LensmapPoint::unwanted_cylinder_d), false, 0.25, false},
                              rx)));
  std::vector<double> prism(count, std::nan(""));
  std::vector<double> colour = field(&LensmapPoint::lateral_colour_arcmin);
  double pmax = 0, cmax = 0;
  for (size_t i = 0; i < count; ++i)
    if (r.points[i].valid) {
      prism[i] = std::hypot(r.points[i].prism_h, r.points[i].prism_v);
      pmax = std::max(pmax, prism[i]);
      cmax = std::max(cmax, colour[i]);
    }
  put(writeSketch(dir, "prism",
                  sketchField(r,
                              {"prism", "Prism as worn (arrows: base direction): " + r.element, "prism D", prism, false,
                               niceStep(std::max(pmax, 1e-3), 10), true},
                              rx)));
  put(writeSketch(dir, "lateral_colour",
                  sketchField(r,
                              {"lateral_colour", "Lateral colour (F' - C'): " + r.element, "arcmin", colour, false,
                               niceStep(std::max(cmax, 1e-3), 10), false},
                              rx)));
  put(writeSketch(dir, "distortion", sketchDistortion(r, distortion)));
  return out;
}

std::vector<double> isoLevels(double lo, double hi, double step, size_t max_levels) {
  std::vector<double> v;
  if (!(step > 0) || !(hi > lo)) return v;
  for (long k = long(std::floor(lo / step)); double(k) * step <= hi; ++k) {
    const double level = double(k) * step;
    if (level > lo && level < hi) v.push_back(level);
  }
  if (v.size() > max_levels) {
    const size_t every = (v.size() + max_levels - 1) / max_levels;
    std::vector<double> w;
    for (size_t i = 0; i < v.size(); i += every) w.push_back(v[i]);
    v = w;
  }
  return v;
}

std::vector<std::pair<Vec2, Vec2>> isoSegments(const std::vector<double>& values, int n, double level) {
  std::vector<std::pair<Vec2, Vec2>> out;
  auto at = [&](int x, int y) { return values[size_t(y) * size_t(n) + size_t(x)]; };
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const double v[4] = {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)};
      if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && std::isfinite(v[3]))) continue;
      const Vec2 c[4] = {Vec2(x, y), Vec2(x + 1, y), Vec2(x + 1, y + 1), Vec2(x, y + 1)};
      std::vector<Vec2> cut;
      for (int e = 0; e < 4; ++e) {
        const double a = v[e], b = v[(e + 1) % 4];
        if ((a < level) != (b < level)) cut.push_back(c[e] + (c[(e + 1) % 4] - c[e]) * ((level - a) / (b - a)));
      }
      if (cut.size() == 2) out.push_back({cut[0], cut[1]});
      if (cut.size() == 4) {
        // Saddle: decide by the centre's value.
        const double mid = 0.25 * (v[0] + v[1] + v[2] + v[3]);
        if ((mid < level) == (v[0] < level)) {
          out.push_back({cut[0], cut[1]});
          out.push_back({cut[2], cut[3]});
        } else {
          out.push_back({cut[0], cut[3]});
          out.push_back({cut[1], cut[2]});
        }
      }
    }
  return out;
}

}  // namespace pvrr::app

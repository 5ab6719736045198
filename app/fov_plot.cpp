#include "app/fov_plot.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "app/sketch.h"
#include "pvrr/base/format.h"

namespace pvrr::app {

namespace {

constexpr double kDepthScale_m = 20;                      // fovDepthAxis: this far behind lies at mid-width
constexpr double kOutwardMin_m = -3, kOutwardMax_m = 10;  // lateral range shown, outward from the outermost point

const Rgb kPass{0.15, 0.65, 0.25}, kFail{0.85, 0.15, 0.12}, kLeftEye{0.12, 0.35, 0.85}, kRightEye{0.95, 0.55, 0.05},
    kObstructed{0.35, 0.35, 0.35}, kVehicle{0.55, 0.58, 0.62};

struct PlotArea {
  double left = 90, top = 86, width = 760, height = 430;
  double u_max = 0;
  double s_sign = 1, y_out = 0;  // outward s = s_sign (y - y_out)
  Vec2 px(Vec2 vehicle_xy) const {
    const double u = fovDepthAxis(std::max(0.0, -vehicle_xy.x));
    const double s = s_sign * (vehicle_xy.y - y_out);
    return Vec2(left + width * u / u_max, top + height * (kOutwardMax_m - s) / (kOutwardMax_m - kOutwardMin_m));
  }
};

// Sutherland-Hodgman against the plot rectangle.
std::vector<Vec2> clip(std::vector<Vec2> poly, const PlotArea& a) {
  auto pass = [&](auto inside, auto cut) {
    std::vector<Vec2> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      const Vec2 p = poly[i], q = poly[(i + 1) % poly.size()];
      const bool pi = inside(p), qi = inside(q);
      if (pi) out.push_back(p);
      if (pi != qi) out.push_back(cut(p, q));
    }
    poly = out;
  };
  const double x0 = a.left, x1 = a.left + a.width, y0 = a.top, y1 = a.top + a.height;
  auto atX = [](Vec2 p, Vec2 q, double x) { return Vec2(x, p.y + (q.y - p.y) * (x - p.x) / (q.x - p.x)); };
  auto atY = [](Vec2 p, Vec2 q, double y) { return Vec2(p.x + (q.x - p.x) * (y - p.y) / (q.y - p.y), y); };
  pass([&](Vec2 p) { return p.x >= x0; }, [&](Vec2 p, Vec2 q) { return atX(p, q, x0); });
  pass([&](Vec2 p) { return p.x <= x1; }, [&](Vec2 p, Vec2 q) { return atX(p, q, x1); });
  pass([&](Vec2 p) { return p.y >= y0; }, [&](Vec2 p, Vec2 q) { return atY(p, q, y0); });
  pass([&](Vec2 p) { return p.y <= y1; }, [&](Vec2 p, Vec2 q) { return atY(p, q, y1); });
  return poly;
}

// A vehicle-frame polygon in plot pixels, its edges split so that the curved depth axis bends them.
std::vector<Vec2> toPx(const std::vector<Vec2>& poly, const PlotArea& a, int split = 1) {
  std::vector<Vec2> out;
  for (size_t i = 0; i < poly.size(); ++i)
    for (int k = 0; k < split; ++k)
      out.push_back(a.px(poly[i] + (poly[(i + 1) % poly.size()] - poly[i]) * (double(k) / split)));
  return out;
}

std::string pct(double f) { return fmt("%.0f %%", 100 * f); }

}  // namespace

double fovDepthAxis(double behind_m) { return behind_m / (behind_m + kDepthScale_m); }

std::vector<std::string> writeFovPlot(const std::string& dir, const std::string& title, const VehicleFrame& frame,
                                      bool driver_side, const std::vector<const EyeFootprint*>& eyes,
                                      const std::vector<FovPlotZone>& zones, const FovOptions& options) {
  Sketch k;
  k.width = 940;
  size_t eye_lines = 0;  // one legend line per eye named (an eye ellipse's samples share their eye's)
  for (const char* eye : {"left", "right"})
    eye_lines += std::any_of(eyes.begin(), eyes.end(), [&](const EyeFootprint* f) { return f->eye == eye; }) ? 1 : 0;
  k.height = int(86 + 430 + 66 + 18 * (eye_lines + 1) + 22 + 18 * zones.size() + 10);
  PlotArea a;
  a.u_max = fovDepthAxis(options.horizon_m);
  const bool left = (frame.desc().driver_side == VehicleDesc::Side::Left) == driver_side;
  a.s_sign = left ? 1 : -1;
  a.y_out = frame.outermost(left).y;
  const double x1 = a.left + a.width, y1 = a.top + a.height;

  bool all_pass = !zones.empty(), all_verified = true;
  for (const FovPlotZone& z : zones)
    all_pass = all_pass && z.result->pass, all_verified = all_verified && z.zone->verified;
  // A verdict on values not confirmed in the regulation's text says so, on the plot as in fov.json.
  const std::string unverified = all_verified ? "" : " (regulation values unverified: fov.json \"verified\")";
  k.texts.push_back({k.width / 2.0, 28, title, 17, 1, kBlack});
  k.texts.push_back({k.width / 2.0, 52,
                     zones.empty()
                         ? "no regulation zones"
                         : (all_pass ? "PASS: every zone covered" : "FAIL: see the red zones and the marked points") +
                               unverified,
                     15, 1,
                     zones.empty() ? kDark
                     : all_pass    ? kPass
                                   : kFail});

  // The road (light) and the vehicle's own side (grey band inside its outermost point).
  k.rects.push_back({a.left, a.top, x1, y1, {0.96, 0.96, 0.94}});
  const Vec2 car_top = a.px(Vec2(0, a.y_out));
  k.rects.push_back({a.left, car_top.y, x1, y1, {0.86, 0.87, 0.89}});
  k.texts.push_back({a.left + 8, y1 - 10, "vehicle side (inside its outermost point)", 11, 0, kVehicle});

  // Grid: depth lines, lateral lines every metre (labelled every 2 m).
  for (double d : {0.0, 4.0, 10.0, 20.0, 30.0, 50.0, 100.0, 200.0}) {
    const double x = a.px(Vec2(-d, a.y_out)).x;
    k.lines.push_back({{Vec2(x, a.top), Vec2(x, y1)}, kGrey, 1});
    k.texts.push_back({x, y1 + 18, fmt("%g", d), 11, 1, kBlack});
  }
  k.texts.push_back({x1, y1 + 18, "horizon", 11, 1, kBlack});
  k.texts.push_back(
      {a.left + a.width / 2, y1 + 40, "metres behind the ocular points (compressed: d / (d + 20 m))", 12, 1, kBlack});
  for (double s = kOutwardMin_m; s <= kOutwardMax_m + 1e-9; s += 1) {
    const double y = a.top + a.height * (kOutwardMax_m - s) / (kOutwardMax_m - kOutwardMin_m);
    k.lines.push_back({{Vec2(a.left, y), Vec2(x1, y)}, s == 0 ? kDark : kGrey, s == 0 ? 1.5 : 1});
    if (int(s) % 2 == 0) k.texts.push_back({a.left - 8, y + 4, fmt("%g", s), 11, 2, kBlack});
  }
  k.texts.push_back({a.left - 8, a.top - 10, "metres outward from the outermost point", 12, 0, kBlack});

  // Zones.
  for (const FovPlotZone& z : zones) {
    const Rgb c = z.result->pass ? kPass : kFail;
    const std::vector<Vec2> p = clip(toPx(z.result->polygon, a, 64), a);
    k.polys.push_back({p, c, 0.28});
    std::vector<Vec2> ring = p;
    if (!ring.empty()) ring.push_back(ring.front());
    k.lines.push_back({ring, c, 2});
  }
  // Obstructed cells (grey) and each eye's footprint outline.
  for (const EyeFootprint* f : eyes) {
    const int n = f->n;
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const size_t c[4] = {size_t(j) * size_t(n) + size_t(i), size_t(j) * size_t(n) + size_t(i + 1),
                             size_t(j + 1) * size_t(n) + size_t(i + 1), size_t(j + 1) * size_t(n) + size_t(i)};
        bool obs = false, back = false;
        for (size_t q : c) {
          obs |= f->fate[q] == RayFate::Obstructed;
          back |= f->fate[q] == RayFate::Back;
        }
        if (!obs || back) continue;
        std::vector<Vec2> cell;
        for (size_t q : c) cell.push_back(f->road[q]);
        const std::vector<Vec2> p = clip(toPx(cell, a), a);
        if (p.size() >= 3) k.polys.push_back({p, kObstructed, 0.35});
      }
  }
  for (const EyeFootprint* f : eyes) {
    const Rgb c = f->eye == "left" ? kLeftEye : kRightEye;
    // The outline as polylines broken where it leaves the plot (the boundary samples are dense).
    std::vector<Vec2> p = toPx(f->outline, a);
    if (!p.empty()) p.push_back(p.front());
    std::vector<Vec2> piece;
    for (const Vec2& q : p) {
      if (q.x >= a.left && q.x <= x1 && q.y >= a.top && q.y <= y1) {
        piece.push_back(q);
        continue;
      }
      if (piece.size() > 1) k.lines.push_back({piece, c, 2, f->eye == "right"});
      piece.clear();
    }
    if (piece.size() > 1) k.lines.push_back({piece, c, 2, f->eye == "right"});
  }
  // Zone points no eye of the zone sees (the gaps).
  for (const FovPlotZone& z : zones)
    for (const Vec2& m : z.result->missed) {
      const Vec2 p = a.px(m);
      if (p.x < a.left || p.x > x1 || p.y < a.top || p.y > y1) continue;
      k.polys.push_back(
          {{p + Vec2(-1.2, -1.2), p + Vec2(1.2, -1.2), p + Vec2(1.2, 1.2), p + Vec2(-1.2, 1.2)}, {0.6, 0.05, 0.05}, 1});
    }

  // Legend and the figures per zone.
  double ly = y1 + 66;
  for (const char* eye : {"left", "right"}) {
    // One line per eye; several footprints of one eye (an eye ellipse's samples) share it.
    int count = 0;
    bool horizon = false;
    double reach = 0;
    for (const EyeFootprint* f : eyes)
      if (f->eye == eye) {
        ++count;
        horizon = horizon || f->sees_horizon;
        reach = std::max(reach, f->reach_m);
      }
    if (count == 0) continue;
    const bool right = std::string(eye) == "right";
    k.lines.push_back({{Vec2(a.left, ly - 4), Vec2(a.left + 30, ly - 4)}, right ? kRightEye : kLeftEye, 2, right});
    const std::string what = horizon ? "reaches the horizon" : fmt("road reach %.0f m, no horizon", reach);
    const std::string whose =
        count == 1 ? std::string(eye) + " eye footprint: "
                   : std::string(eye) + " eye footprints (" + std::to_string(count) + " eye-ellipse samples): ";
    k.texts.push_back({a.left + 38, ly, whose + what, 12, 0, kBlack});
    ly += 18;
  }
  k.polys.push_back({{Vec2(a.left, ly - 12), Vec2(a.left + 30, ly - 12), Vec2(a.left + 30, ly), Vec2(a.left, ly)},
                     kObstructed,
                     0.35});
  k.texts.push_back(
      {a.left + 38, ly, "obstructed (vehicle.obstructions)      dots: zone points not seen clearly", 12, 0, kBlack});
  ly += 22;
  for (const FovPlotZone& z : zones) {
    const Rgb c = z.result->pass ? kPass : kFail;
    k.texts.push_back({a.left, ly,
                       (z.result->pass ? "PASS  " : "FAIL  ") + z.zone->name + ": covered " +
                           pct(z.result->covered_fraction) + ", obstructed " + pct(z.result->obstructed_fraction) +
                           (z.zone->verified ? "" : " (values unverified)"),
                       12, 0, c});
    ly += 18;
  }
  return writeSketch(dir, "fov", k);
}

std::vector<std::string> writeMagnificationPlot(const std::string& dir, const std::string& title,
                                                const SurfaceFigures& s) {
  Sketch k;
  k.width = 640;
  k.height = 600;
  const double left = 70, top = 80, size = 440;
  const int m = s.n - 1;
  double lo = kInf, hi = -kInf;
  for (double v : s.magnification)
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  if (!(hi > lo)) {  // a plane mirror: one value
    lo = std::isfinite(lo) ? lo - 0.01 : 0.99;
    hi = lo + 0.02;
  }
  // Yellow (low magnification: the most compressed image) to dark blue (the highest).
  const std::vector<Rgb> stops = {{1.0, 0.95, 0.55}, {0.55, 0.8, 0.6}, {0.2, 0.55, 0.7}, {0.1, 0.2, 0.5}};
  auto colour = [&](double v) {
    double t = std::clamp((v - lo) / (hi - lo), 0.0, 1.0) * double(stops.size() - 1);
    const size_t i = std::min(size_t(t), stops.size() - 2);
    t -= double(i);
    const Rgb &a = stops[i], &b = stops[i + 1];
    return Rgb{a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
  };
  k.texts.push_back({k.width / 2.0, 28, title, 16, 1, kBlack});
  k.texts.push_back({k.width / 2.0, 50,
                     "magnification of distant objects relative to a plane mirror: " +
                         fmt("%.3f", s.magnification_min) + " to " + fmt("%.3f", s.magnification_max) + " (principal)",
                     12, 1, kDark});
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const double v = s.magnification[size_t(j) * size_t(m) + size_t(i)];
      const double x0 = left + size * i / m, x1 = left + size * (i + 1) / m;
      const double y1 = top + size * (m - j) / m, y0 = top + size * (m - j - 1) / m;
      k.rects.push_back({x0, y0, x1, y1, std::isfinite(v) ? colour(v) : kGrey});
    }
  k.lines.push_back({{Vec2(left, top), Vec2(left + size, top), Vec2(left + size, top + size), Vec2(left, top + size),
                      Vec2(left, top)},
                     kBlack,
                     1});
  k.texts.push_back(
      {left + size / 2, top + size + 24, "mirror parameter u (as in the scene's element frame)", 12, 1, kBlack});
  k.texts.push_back({left, top - 8, "v", 12, 0, kBlack});
  // Colour bar with five labels (geometric mean of the principal magnifications).
  const double bx = left + size + 30, bw = 24;
  for (int q = 0; q < 100; ++q) {
    const double t0 = q / 100.0, t1 = (q + 1) / 100.0;
    k.rects.push_back(
        {bx, top + size * (1 - t1), bx + bw, top + size * (1 - t0), colour(lo + (hi - lo) * (t0 + t1) / 2)});
  }
  for (int q = 0; q <= 4; ++q) {
    const double t = q / 4.0;
    k.texts.push_back({bx + bw + 6, top + size * (1 - t) + 4, fmt("%.3f", lo + (hi - lo) * t), 11, 0, kBlack});
  }
  k.texts.push_back({bx, top - 8, "x", 12, 0, kBlack});
  return writeSketch(dir, "magnification", k);
}

}  // namespace pvrr::app

// pvrr/analysis/fov_eyes: an eye ellipse of zero size is the two ocular points; a plane mirror's zone coverage
// over the ellipse grows with its size; the samples lie on the ellipsoid as described; the car mirror's outlines are
// simple and their union over the ellipse is one loop holding every sample's footprint.
#include "pvrr/analysis/fov_eyes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "pvrr/scene/scene_json.h"

#include "tests/pvrr/analysis/fov_test_scenes.h"

namespace pvrr {
namespace {

// A J941-like size (full axes along forward, left, up; m): the shape of a driver's eye scatter, not a value
// claimed from the standard.
const Vec3 kAxes(0.20, 0.06, 0.09);

std::vector<ZoneResult> coverage(const Scene& scene, const VehicleFrame& frame, const std::vector<EyeSample>& eyes,
                                 const std::vector<FovZone>& zones, std::vector<EyeFootprint>* feet_out = nullptr) {
  const RayScene rays(scene);
  FovOptions o;
  o.samples = 61;  // the footprints' outlines to ~1.5 % of the mirror: the comparisons are between equal samplings
  std::vector<EyeFootprint> feet;
  for (const EyeSample& e : eyes) feet.push_back(traceFootprint(rays, 0, frame, e.world, e.eye, o));
  std::vector<const EyeFootprint*> ptrs;
  for (const EyeFootprint& f : feet) ptrs.push_back(&f);
  std::vector<ZoneResult> out;
  for (const FovZone& z : zones) out.push_back(evaluateZone(z, frame, ptrs, o));
  if (feet_out) *feet_out = std::move(feet);
  return out;
}

TEST(FovEyes, SamplesLieOnTheTiltedEllipsoid) {
  const Scene scene = test::planeMirror(0.3, 0.24, 0, 0);
  const VehicleFrame frame = test::frameOf(scene);
  VehicleDesc::EyeEllipse e;
  e.axes_m = kAxes;
  e.tilt_deg = 12;
  const std::vector<EyeSample> s = eyeEllipseSamples(frame, e);
  ASSERT_EQ(s.size(), 30u);
  const double t = 12 * kPi / 180;
  for (const EyeSample& p : s) {
    // Back into the ellipsoid's axes: undo the tilt, divide by the half axes; the result is the unit sample.
    const Vec3 v = frame.toVehicle(p.world) - frame.eye(p.eye == "left");
    const Vec3 d(v.x * std::cos(t) - v.z * std::sin(t), v.y, v.x * std::sin(t) + v.z * std::cos(t));
    EXPECT_NEAR(glm::length(d / (0.5 * kAxes) - p.unit), 0, 1e-12);
  }
  // The forward axis end is lower than the centre by half the axis times sin(tilt).
  const Vec3 fwd = frame.toVehicle(s[1].world) - frame.eye(true);
  EXPECT_NEAR(fwd.z, -0.5 * kAxes.x * std::sin(t), 1e-12);
  EXPECT_NEAR(fwd.x, 0.5 * kAxes.x * std::cos(t), 1e-12);
}

TEST(FovEyes, ZeroSizeEllipseIsTheOcularPoints) {
  // A plane mirror turned so that both zones are partly covered: a size-0 ellipse gives exactly the two ocular
  // points' result (one sample per eye, the same footprints, the same fractions).
  const Scene scene = test::planeMirror(0.3, 0.24, 4, -3);
  const VehicleFrame frame = test::frameOf(scene);
  VehicleDesc::EyeEllipse e;
  e.axes_m = kAxes;
  const std::vector<EyeSample> zero = eyeEllipseSamples(frame, e, 0.0);
  ASSERT_EQ(zero.size(), 2u);
  const std::vector<EyeSample> ocular = {{"left", frame.desc().eye_left, Vec3(0)},
                                         {"right", frame.desc().eye_right, Vec3(0)}};
  std::vector<EyeFootprint> fz, fo;
  const std::vector<ZoneResult> rz = coverage(scene, frame, zero, test::classIII(), &fz);
  const std::vector<ZoneResult> ro = coverage(scene, frame, ocular, test::classIII(), &fo);
  for (size_t k = 0; k < rz.size(); ++k) {
    std::printf("zone %zu: covered %.4f (ocular points %.4f)\n", k, rz[k].covered_fraction, ro[k].covered_fraction);
    EXPECT_EQ(rz[k].covered_fraction, ro[k].covered_fraction);
    EXPECT_EQ(rz[k].obstructed_fraction, ro[k].obstructed_fraction);
    EXPECT_EQ(rz[k].pass, ro[k].pass);
  }
  EXPECT_LT(ro[1].covered_fraction, 1);  // the case is not trivially full coverage
  EXPECT_GT(ro[1].covered_fraction, 0);
  const std::vector<Vec2> uz = unionOfPolygons({fz[0].outline, fz[1].outline});
  const std::vector<std::vector<Vec2>> uo = polygonUnion(fo[0].outline, fo[1].outline);
  ASSERT_EQ(uo.size(), 1u);
  ASSERT_EQ(uz.size(), uo[0].size());
  for (size_t i = 0; i < uz.size(); ++i) EXPECT_EQ(uz[i], uo[0][i]);
}

TEST(FovEyes, PlaneMirrorCoverageGrowsWithTheEllipse) {
  // The mis-aimed plane mirror: the near strip is partly covered from the ocular points. Moving the head over a
  // larger ellipse sees more of it: the covered fraction never falls as the ellipse grows, and grows overall.
  const Scene scene = test::planeMirror(0.3, 0.24, 4, -3);
  const VehicleFrame frame = test::frameOf(scene);
  VehicleDesc::EyeEllipse e;
  e.axes_m = kAxes;
  e.tilt_deg = 12;
  std::vector<double> prev;
  std::vector<double> first;
  for (const double scale : {0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 1.0}) {
    const std::vector<ZoneResult> r = coverage(scene, frame, eyeEllipseSamples(frame, e, scale), test::classIII());
    std::printf("scale %.2f: covered %.4f, %.4f\n", scale, r[0].covered_fraction, r[1].covered_fraction);
    for (size_t k = 0; k < r.size(); ++k) {
      if (!prev.empty()) {
        EXPECT_GE(r[k].covered_fraction, prev[k]) << "zone " << k << " at scale " << scale;
      }
      if (first.size() < r.size()) first.push_back(r[k].covered_fraction);
    }
    prev.clear();
    for (const ZoneResult& z : r) prev.push_back(z.covered_fraction);
  }
  EXPECT_GT(prev[1], first[1] + 0.02);
}

TEST(FovEyes, UnionOfPolygonsIsOneLoopOrNothing) {
  auto square = [](double x0, double y0, double w) {
    return std::vector<Vec2>{Vec2(x0, y0), Vec2(x0 + w, y0), Vec2(x0 + w, y0 + w), Vec2(x0, y0 + w)};
  };
  // Three overlapping squares (no shared edge lines: polygonUnion does not take those): one loop, the area of their
  // union, 3 x 100 less the overlaps 5 x 7 (first and second) and 4 x 7 (second and third).
  const std::vector<Vec2> u = unionOfPolygons({square(0, 0, 10), square(5, 3, 10), square(11, 6, 10)});
  ASSERT_FALSE(u.empty());
  EXPECT_NEAR(signedArea(u), 300 - 35 - 28, 1e-9);
  // A disjoint one: two loops, which the union does not represent.
  EXPECT_TRUE(unionOfPolygons({square(0, 0, 10), square(20, 0, 10)}).empty());
  // One polygon is its own union.
  EXPECT_NEAR(signedArea(unionOfPolygons({square(0, 0, 3)})), 9, 1e-12);
}

// Every pair of non-adjacent edges checked for a crossing (touching counts), independently of firstSelfCrossing.
int selfCrossings(const std::vector<Vec2>& p) {
  auto cross = [](Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; };
  int count = 0;
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      const Vec2 a = p[i], d = p[(i + 1) % n] - a, b = p[j], e = p[(j + 1) % n] - b;
      const double den = cross(d, e);
      if (den == 0) continue;
      const double t = cross(b - a, e) / den, u = cross(b - a, d) / den;
      count += t >= 0 && t <= 1 && u >= 0 && u <= 1;
    }
  return count;
}

// The distance from p to the closed polygon's boundary.
double boundaryDistance(Vec2 p, const std::vector<Vec2>& poly) {
  double best = kInf;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], d = poly[(i + 1) % poly.size()] - a;
    const double t = glm::dot(d, d) > 0 ? std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0) : 0.0;
    best = std::min(best, glm::length(p - (a + t * d)));
  }
  return best;
}

// A sample's footprint vertex may lie this far outside the union (m): the crossing points are computed once per
// polygon, and the union's slivers (unionOfPolygons) are dropped, all at the horizon 1 km away.
constexpr double kUnionTol_m = 1e-3;

TEST(FovEyes, MakeSimpleCutsAFold) {
  // A square with a thin whisker out of its top edge that turns back across itself (a fold like the horizon's):
  // the whisker goes out along y = 10 to x = 20, then back slightly above to x = 9, crossing its own start.
  std::vector<Vec2> p{Vec2(0, 0), Vec2(10, 0), Vec2(10, 10), Vec2(20, 10.01), Vec2(9, 9.99), Vec2(0, 10)};
  ASSERT_GT(selfCrossings(p), 0);
  const double cut = makeSimple(p);
  EXPECT_EQ(selfCrossings(p), 0);
  EXPECT_GT(signedArea(p), 0);
  EXPECT_NEAR(signedArea(p), 100, 0.1);  // the square, less the sliver between (9, 9.99) and (10, 10)
  EXPECT_GT(cut, 0);
  EXPECT_LT(cut, 0.2);
  // A simple polygon is left as it is.
  std::vector<Vec2> q{Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  EXPECT_EQ(makeSimple(q), 0);
  EXPECT_EQ(q.size(), 4u);
}

// The car mirror, turned 6 deg about the vertical (its near strip then 99 % covered from the ocular points, so the
// footprints differ in where they reach), over a J941-like eye ellipse: every sample's outline (folded at the
// horizon as traced: the cut area reports it) is simple, and the union over each eye and over all samples is one
// loop that holds every sample's footprint.
TEST(FovEyes, CarMirrorOutlinesAreSimpleAndTheirUnionHoldsEverySample) {
  const SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/car-mirror.json",
                                   {"elements[0].pose.normal=[0.47697, 0.1238, 0.87021]",
                                    "vehicle.eye_ellipse={\"axes\": [0.2, 0.06, 0.09], \"tilt_deg\": 12}"});
  const Scene scene = buildScene(desc);
  const VehicleFrame frame(*desc.vehicle);
  const RayScene rays(scene);
  FovOptions o;
  o.samples = 61;
  std::vector<std::vector<Vec2>> all, left;
  double cut = 0;
  for (const EyeSample& e : eyeEllipseSamples(frame, *desc.vehicle->eye_ellipse)) {
    const EyeFootprint f = traceFootprint(rays, 0, frame, e.world, e.eye, o);
    EXPECT_EQ(selfCrossings(f.outline), 0) << e.eye;
    EXPECT_GT(signedArea(f.outline), 0);
    // What the repair cuts is a sliver at the horizon, not a part of the footprint.
    EXPECT_LT(f.outline_cut_area_m2, 1e-4 * signedArea(f.outline));
    cut = std::max(cut, f.outline_cut_area_m2);
    all.push_back(f.outline);
    if (e.eye == "left") left.push_back(f.outline);
  }
  ASSERT_EQ(all.size(), 30u);
  EXPECT_GT(cut, 0);  // the traced outlines did fold (the test is not vacuous)
  for (const auto* polys : {&left, &all}) {
    const std::vector<Vec2> u = unionOfPolygons(*polys);
    ASSERT_FALSE(u.empty());
    EXPECT_EQ(selfCrossings(u), 0);
    const double area = signedArea(u);
    double worst = 0;  // the largest distance of a sample's vertex outside the union
    for (const std::vector<Vec2>& p : *polys) {
      EXPECT_GE(area, signedArea(p));
      for (const Vec2& v : p)
        if (!insidePolygon(u, v)) worst = std::max(worst, boundaryDistance(v, u));
    }
    std::printf("union of %zu outlines: %zu points, area %.6g m^2; sample vertices outside it by at most %.3g m\n",
                polys->size(), u.size(), area, worst);
    EXPECT_LT(worst, kUnionTol_m);
  }
}

}  // namespace
}  // namespace pvrr

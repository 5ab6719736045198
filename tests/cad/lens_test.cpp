// Lens solids: thicknesses from the sag formula, edge-thickness specification, and rejection of surfaces that
// cross or are undefined inside the outline.
#include <gtest/gtest.h>

#include <cmath>

#include "cad/error.h"
#include "cad/lens.h"

namespace pvrr::cad {
namespace {

// Thicknesses of ~1e-3 m from sags of ~1e-3 m: roundoff ~1e-18 m; 1e-15 m leaves room for the naive
// reference formula's cancellation.
constexpr double kThicknessAbs = 1e-15;

// Naive sphere sag |R| - sqrt(R^2 - r^2) (magnitude), in long double.
double sagMagnitude(double R, double r) {
  const long double Rl = std::abs(R);
  return double(Rl - std::sqrt(Rl * Rl - (long double)r * r));
}

TEST(Lens, PlusTwoDioptreLensFromRadii) {
  // Equiconvex, n = 1.5: lensmaker P = (n - 1)(1/R1 - 1/R2) = 2 D gives R1 = -R2 = 2 (n - 1) / P = 0.5 m.
  const double n = 1.5, power_d = 2.0;
  const double R1 = 2 * (n - 1) / power_d, R2 = -R1;
  const double diameter = 0.05, edge = 0.001;
  const Outline disc = Outline::circle(diameter);
  // Front bulges towards the eye (+z): R > 0. Back bulges away: centre of curvature in front, R < 0.
  const LensSolid lens = makeLens(makeSphere(R1, disc), makeSphere(R2, disc), disc, 0.0, edge, "plus lens");
  const double s = sagMagnitude(R1, 0.5 * diameter);
  EXPECT_NEAR(lens.centre_thickness, edge + 2 * s, kThicknessAbs);
  EXPECT_NEAR(lens.thicknessAt(0, 0), lens.centre_thickness, kThicknessAbs);
  EXPECT_NEAR(lens.edgeThicknessMin(), edge, kThicknessAbs);
  EXPECT_NEAR(lens.minimumThickness(), edge, kThicknessAbs);
  EXPECT_EQ(lens.front->zVertex(), 0.0);
  EXPECT_EQ(lens.back->zVertex(), -lens.centre_thickness);
  // Half way out: thickness = t_c - 2 sag(r).
  EXPECT_NEAR(lens.thicknessAt(0.01, -0.005), lens.centre_thickness - 2 * sagMagnitude(R1, std::hypot(0.01, 0.005)),
              kThicknessAbs);
  // A larger given centre thickness is kept (the edge requirement only raises it).
  const LensSolid thick = makeLens(makeSphere(R1, disc), makeSphere(R2, disc), disc, 0.004, edge, "plus lens");
  EXPECT_EQ(thick.centre_thickness, 0.004);
}

TEST(Lens, MinusLensEdgeIsThickest) {
  // Front R = 1 m, back R = 0.25 m (both convex towards the eye): (n - 1)(1 - 4) = -1.5 D at n = 1.5.
  const Outline rect = Outline::rectangle(0.05, 0.03, 0.005);
  const double tc = 0.0018;
  const LensSolid lens = makeLens(makeSphere(1.0, rect), makeSphere(0.25, rect), rect, tc, 0.0, "minus lens");
  EXPECT_EQ(lens.centre_thickness, tc);
  // Thickness = t_c + sag_back - sag_front, largest at the far corners, smallest at the centre.
  const Vec2 far = rect.fromSquare(Vec2(1, 1));
  const double r = glm::length(far);
  EXPECT_NEAR(lens.thicknessAt(far.x, far.y), tc + sagMagnitude(0.25, r) - sagMagnitude(1.0, r), kThicknessAbs);
  EXPECT_NEAR(lens.minimumThickness(), tc, kThicknessAbs);
  // Along the boundary the thinnest point is the middle of the long sides, at r = 0.015.
  EXPECT_NEAR(lens.edgeThicknessMin(), tc + sagMagnitude(0.25, 0.015) - sagMagnitude(1.0, 0.015), kThicknessAbs);
}

TEST(Lens, CrossingSurfacesAreRejected) {
  const Outline disc = Outline::circle(0.05);
  // Strongly curved plus lens with too little centre thickness: the surfaces cross before the edge
  // (2 sag(25 mm, 0.2 m) = 3.1 mm > 1 mm).
  try {
    makeLens(makeSphere(0.2, disc), makeSphere(-0.2, disc), disc, 0.001, 0.0, "lens.json: elements[2]");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("lens.json: elements[2]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cross or touch"), std::string::npos) << msg;
  }
  // Identical surfaces touch everywhere with zero centre thickness.
  EXPECT_THROW(makeLens(makeSphere(0.5, disc), makeSphere(0.5, disc), disc, 0.0, 0.0, "lens"), Error);
  // Zero centre thickness, a concave front (R < 0, rising towards the eye) and a plane back: they touch at
  // the vertex.
  EXPECT_THROW(makeLens(makeSphere(-0.5, disc), makePlane(disc), disc, 0.0, 0.0, "lens"), Error);
}

TEST(Lens, UndefinedSagAndBadArgumentsAreRejected) {
  const Outline disc = Outline::circle(0.05);
  try {
    makeLens(makeSphere(0.02, disc), makePlane(disc), disc, 0.01, 0.0, "steep lens");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("steep lens: front surface (sphere R=0.02 m) is undefined"), std::string::npos) << msg;
  }
  EXPECT_THROW(makeLens(nullptr, makePlane(disc), disc, 0.01, 0, "lens"), Error);
  EXPECT_THROW(makeLens(makePlane(disc), makePlane(disc), disc, -0.01, 0, "lens"), Error);
  EXPECT_THROW(makeLens(makePlane(disc), makePlane(disc), disc, 0.01, std::nan(""), "lens"), Error);
}

}  // namespace
}  // namespace pvrr::cad

// Spectacle prescriptions and aspheric lenses: the prescription -> radii closed form (pvrr/scene/scene_build.h), the
// powers the reference tracer measures through a toric lens built from a prescription (the cylinder appears
// between the principal meridians, along the axis the scene names), and pvrr mode against the reference
// tracer for a toric and an aspheric spectacle lens, on OSMesa and on EGL.
//
// Set-up: models/spectacle-lens.json (a -3.00 D CR-39 lens 12 mm in front of the eye, attached to the
// observer, 50 x 40 mm ellipse, t = 2 mm) at 160 x 120, with its two spherical surfaces replaced by
//   toric:    the prescription -2.00 DS / -1.50 DC x 30 (the build's default base curve), or
//   aspheric: the same eye-side surface as an asphere (same vertex radius, conic -1, A4 = 20 m^-3), which
//             keeps the paraxial power at -3.00 D and changes the rim.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/accuracy.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// prescriptionRadii inverts the thick-lens formula in double: F_v recomputed from its radii is exact to a
// few ulps of the ~10 D surface powers (~1e-14 D); 1e-9 D leaves room for the divisions and nothing more.
constexpr double kClosedFormD = 1e-9;
// Powers measured by tracing: two rays 1 mm either side of the axis in a principal meridian, crossing the
// axis behind the eye-side vertex at 1 / F_v. The surfaces' spherical aberration at 1 mm (h / R ~ 1 / 58)
// shifts that by ~(h / R)^2 of the power, < 0.002 D here; 0.02 D (an eighth of the 0.125 D prescription
// step) bounds it. An axis swapped by 90 deg would be off by the full cylinder, 1.5 D.
constexpr double kTracedPowerD = 0.02;
constexpr double kRayHeight_m = 1e-3;
// A ray in a principal meridian stays in it (the surface is mirror-symmetric about that plane): its
// off-plane position and direction are rounding only.
constexpr double kOffMeridian = 1e-9;
// Issue 6's bound for lenses at the default tessellation (median over lens pixels, as renderer_test.cpp). The
// shipped spherical spectacle lens measures 0.68' (docs/accuracy.md, and pvrr compare at 160 x 120); the
// toric and aspheric variants measure 0.44' and 0.68' here.
constexpr double kMedianArcmin = 1.0;

// The spectacle-lens model, its two spherical surfaces replaced by `surfaces` (JSON members).
SceneDesc spectacleWith(const std::string& surfaces, const std::vector<std::string>& sets = {}) {
  const std::string path = PVRR_SOURCE_DIR "/models/spectacle-lens.json";
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::regex front_back(R"re("front"\s*:\s*\{[^}]*\}\s*,\s*"back"\s*:\s*\{[^}]*\}\s*,)re");
  std::smatch m;
  if (!std::regex_search(text, m, front_back)) throw std::runtime_error(path + ": no front and back surfaces to replace");
  const std::string edited = m.prefix().str() + surfaces + "," + m.suffix().str();
  std::vector<std::string> all = {"observer.image_size=[160,120]"};
  all.insert(all.end(), sets.begin(), sets.end());
  return parseScene(edited, path + " (edited)", PVRR_SOURCE_DIR "/models", all);
}

std::string prescription(double sphere, double cylinder, double axis_deg) {
  std::ostringstream o;
  o << R"("prescription": {"sphere_d": )" << sphere << R"(, "cylinder_d": )" << cylinder << R"(, "axis_deg": )"
    << axis_deg << "}";
  return o.str();
}

// The spectacle model's eye-side radius (models/spectacle-lens.json) as an asphere of the same vertex radius.
const char* kAsphericSurfaces =
    R"("front": {"type": "asphere", "radius": -0.070925, "conic": -1, "coefficients": [20]},
       "back": {"type": "sphere", "radius": -0.1245})";
const char* kSphericalSurfaces =
    R"("front": {"type": "sphere", "radius": -0.070925}, "back": {"type": "sphere", "radius": -0.1245})";

// Back vertex power from surface radii (pvrr/scene/scene_build.cpp's convention): F1 the object-side ("back")
// surface, F2 the eye-side ("front") one.
double backVertexPower(double r_back, double r_front, double n, double t) {
  const double f1 = std::isfinite(r_back) ? -(n - 1.0) / r_back : 0.0;
  const double f2 = std::isfinite(r_front) ? (n - 1.0) / r_front : 0.0;
  return f1 / (1.0 - (t / n) * f1) + f2;
}

// A ray from the object side, parallel to the lens axis at `offset` (lens frame, metres) from it, traced
// through the lens: its exit point and direction, in the lens frame.
struct Exit {
  Vec3 point, dir;
};
Exit traceThrough(const Tracer& tr, const Element& e, const Vec2& offset) {
  const Vec3 o = Vec3(e.local_to_world * Vec4(offset.x, offset.y, -0.05, 1.0));
  const Vec3 d = glm::normalize(Vec3(e.local_to_world * Vec4(0, 0, 1, 0)));
  std::vector<PathSegment> path;
  tr.trace(o, d, 0.0, &path);
  Exit x{Vec3(0), Vec3(0)};
  if (path.size() < 3 || path[0].event != "refract" || path[1].event != "refract") {
    ADD_FAILURE() << "the ray at (" << offset.x << ", " << offset.y << ") does not cross the lens ("
                  << (path.empty() ? "no path" : path[0].event) << ")";
    return x;
  }
  x.point = Vec3(e.world_to_local * Vec4(path[2].origin, 1.0));
  x.dir = glm::normalize(Vec3(e.world_to_local * Vec4(path[2].direction, 0.0)));
  return x;
}

// Back vertex power (D) in the meridian along the unit lens-frame direction `m`: two rays at +-h along m,
// whose exit rays (projected on the meridian plane) cross at z = 1 / F_v from the eye-side vertex (z = 0; +z
// towards the eye). Paraxially the exit slope along m is -h m^T P m for the lens's power matrix P, so off the
// principal meridians this is the power in that meridian, S + C sin^2(angle from the axis).
// `principal`: the rays must also stay in the meridian plane.
double tracedMeridianPower(const Tracer& tr, const Element& e, const Vec2& m, bool principal = true) {
  const Vec2 perp(-m.y, m.x);
  double s[2], ds[2], z[2], dz[2];
  for (int k = 0; k < 2; ++k) {
    const Exit x = traceThrough(tr, e, (k ? -1.0 : 1.0) * kRayHeight_m * m);
    if (principal) {
      EXPECT_LT(std::abs(glm::dot(Vec2(x.point), perp)), kOffMeridian) << "exit point leaves the meridian";
      EXPECT_LT(std::abs(glm::dot(Vec2(x.dir), perp)), kOffMeridian) << "exit direction leaves the meridian";
    }
    s[k] = glm::dot(Vec2(x.point), m);
    ds[k] = glm::dot(Vec2(x.dir), m);
    z[k] = x.point.z;
    dz[k] = x.dir.z;
  }
  // (s0, z0) + a (ds0, dz0) = (s1, z1) + b (ds1, dz1), by Cramer's rule.
  const double det = -ds[0] * dz[1] + ds[1] * dz[0];
  const double a = (-(s[1] - s[0]) * dz[1] + ds[1] * (z[1] - z[0])) / det;
  const double z_cross = z[0] + a * dz[0];
  return 1.0 / z_cross;
}

Vec2 meridian(double deg) { return Vec2(std::cos(radians(deg)), std::sin(radians(deg))); }

TEST(LensPrescription, RadiiGiveTheBackVertexPowersInBothMeridians) {
  struct Rx {
    double sphere, cylinder, base, n, t;
  };
  for (const Rx& rx : {Rx{-2.0, -1.5, 5.0, 1.498, 0.002}, Rx{3.0, -1.0, 9.0, 1.6, 0.004}, Rx{0.5, 2.0, 6.5, 1.74, 0.0025},
                       Rx{-6.0, 0.0, 3.0, 1.67, 0.0015}, Rx{-8.25, -3.75, 1.5, 1.586, 0.001},
                       Rx{1.0, -0.5, defaultBaseCurve(1.0), 1.532, 0.003}}) {
    SCOPED_TRACE(::testing::Message() << rx.sphere << " DS / " << rx.cylinder << " DC, base " << rx.base << " D, n "
                                      << rx.n << ", t " << rx.t);
    const PrescriptionRadii r = prescriptionRadii(rx.sphere, rx.cylinder, rx.base, rx.n, rx.t);
    // The object-side surface carries the base curve, convex towards the object (concave seen from the eye).
    EXPECT_NEAR(-(rx.n - 1.0) / r.back_radius_m, rx.base, kClosedFormD);
    EXPECT_LT(r.back_radius_m, 0);
    EXPECT_NEAR(backVertexPower(r.back_radius_m, r.front_radius_a_m, rx.n, rx.t), rx.sphere, kClosedFormD);
    EXPECT_NEAR(backVertexPower(r.back_radius_m, r.front_radius_b_m, rx.n, rx.t), rx.sphere + rx.cylinder, kClosedFormD);
    if (rx.cylinder == 0) {
      EXPECT_EQ(r.front_radius_a_m, r.front_radius_b_m);
    }
  }
  // Vogel's rule for the default base curve (pvrr/scene/scene_build.cpp).
  EXPECT_DOUBLE_EQ(defaultBaseCurve(2.0), 8.0);
  EXPECT_DOUBLE_EQ(defaultBaseCurve(-4.0), 4.0);
}

// -2.00 DS / -1.50 DC x 30: traced through the built scene, the meridian along the axis (30 deg from the
// lens's local +x) has the sphere power and the one across it sphere + cylinder; at x 120 they swap.
TEST(LensPrescription, ToricLensIsAstigmaticAlongTheSceneAxis) {
  constexpr double kSphere = -2.0, kCylinder = -1.5;
  for (const double axis : {30.0, 120.0}) {
    SCOPED_TRACE(::testing::Message() << "axis " << axis << " deg");
    Scene s = buildScene(spectacleWith(prescription(kSphere, kCylinder, axis)));
    ASSERT_EQ(s.elements.size(), 1u);
    RayScene rays(s);
    const Tracer tr(rays, TraceOptions{});
    const Element& e = s.elements[0];
    const double at30 = tracedMeridianPower(tr, e, meridian(30)), at120 = tracedMeridianPower(tr, e, meridian(120));
    const double at0 = tracedMeridianPower(tr, e, meridian(0), false), at90 = tracedMeridianPower(tr, e, meridian(90), false);
    std::cout << "[ measured ] x " << axis << ": F_v " << at30 << " D at 30 deg, " << at120 << " D at 120 deg\n";
    const bool along = axis == 30.0;
    EXPECT_NEAR(at30, along ? kSphere : kSphere + kCylinder, kTracedPowerD);
    EXPECT_NEAR(at120, along ? kSphere + kCylinder : kSphere, kTracedPowerD);
    EXPECT_NEAR(at120 - at30, along ? kCylinder : -kCylinder, 2 * kTracedPowerD);
    // Off the principal meridians: F(theta) = S + C sin^2(theta - axis) (the power matrix's quadratic form).
    auto sin2 = [&](double deg) { return std::pow(std::sin(radians(deg - axis)), 2); };
    EXPECT_NEAR(at0, kSphere + kCylinder * sin2(0), kTracedPowerD);
    EXPECT_NEAR(at90, kSphere + kCylinder * sin2(90), kTracedPowerD);
  }
}

// The asphere keeps the vertex radius: its paraxial power is the spherical lens's (thick-lens formula from the
// model's radii), in every meridian; at 15 mm from the axis the conic and A4 change the exit direction by
// about (n - 1) times the slope change of the eye-side surface.
TEST(LensPrescription, AsphereKeepsTheParaxialPowerAndChangesTheRim) {
  Scene asph = buildScene(spectacleWith(kAsphericSurfaces)), sph = buildScene(spectacleWith(kSphericalSurfaces));
  RayScene rays_a(asph), rays_s(sph);
  const Tracer ta(rays_a, TraceOptions{}), ts(rays_s, TraceOptions{});
  const Element& e = asph.elements[0];
  const double n = e.dispersion.n_d();
  const double expected = backVertexPower(-0.1245, -0.070925, n, 0.002);
  EXPECT_NEAR(expected, -3.0, 0.01);  // the model's design power
  for (const double deg : {0.0, 45.0, 90.0}) {
    EXPECT_NEAR(tracedMeridianPower(ta, e, meridian(deg)), expected, kTracedPowerD) << deg << " deg";
    EXPECT_NEAR(tracedMeridianPower(ts, sph.elements[0], meridian(deg)), expected, kTracedPowerD) << deg << " deg";
  }
  // Slope of the eye-side sag at r = 15 mm: sphere r / sqrt(R^2 - r^2); conic -1 (paraboloid) r / |R| plus
  // 4 A4 r^3. The exit direction turns by ~(n - 1) times the difference (thin prism).
  const double r = 0.015, R = 0.070925, a4 = 20;
  const double dslope = std::abs(r / std::sqrt(R * R - r * r) - (r / R + 4 * a4 * r * r * r));
  const double estimate = (n - 1.0) * dslope;
  const Exit xa = traceThrough(ta, e, Vec2(r, 0)), xs = traceThrough(ts, sph.elements[0], Vec2(r, 0));
  const double turned = angleBetween(xa.dir, xs.dir);
  std::cout << "[ measured ] asphere at 15 mm: exit direction turned " << arcminutes(turned) << "' (thin-prism estimate "
            << arcminutes(estimate) << "')\n";
  EXPECT_GT(turned, 0.5 * estimate);
  EXPECT_LT(turned, 2.0 * estimate);
}

using test::medianArcmin;

class LensPrescriptionTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(LensPrescriptionTest, ToricAndAsphericLensesMatchTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  struct Case {
    const char* name;
    std::string surfaces;
  };
  for (const Case& c : {Case{"toric -2.00 / -1.50 x 30", prescription(-2.0, -1.5, 30)}, Case{"aspheric", kAsphericSurfaces}}) {
    SCOPED_TRACE(c.name);
    Scene s = buildScene(spectacleWith(c.surfaces));
    RayScene rays(s);
    const Frame ref = Tracer(rays, TraceOptions{}).render();
    gl::Renderer r(s, rays, gl::RendererOptions{});
    const gl::RasterFrame f = r.render(RenderMode::Pvrr);
    ASSERT_EQ(f.seen.size(), ref.seen.size());
    size_t pixels = 0;
    const double median = medianArcmin(ref, f, &pixels);
    std::cout << "[ measured ] " << c.name << " on " << gl::glBackendName(GetParam()) << ": median " << median
              << " arcmin over " << pixels << " lens pixels\n";
    // The lens, 12 mm from the eye and 50 x 40 mm, covers the 50 deg view (bar the corners).
    EXPECT_GT(pixels, size_t(0.9 * ref.width * ref.height));
    EXPECT_LE(median, kMedianArcmin);
    const StageTiming* refr = f.stages.find("refraction");
    ASSERT_NE(refr, nullptr);
    EXPECT_TRUE(refr->ran);
  }
}

PVRR_GL_BACKENDS(LensPrescriptionTest);

}  // namespace
}  // namespace pvrr

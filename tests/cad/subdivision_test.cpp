// Catmull-Clark limit surfaces of OBJ quad cages (cad/cad_import.h: loadSubdivisionCage).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"
#include "cad/model_generator.h"
#include "cad/nurbs.h"

namespace pvrr::cad {
namespace {

namespace fs = std::filesystem;

// The limit surface of a regular grid IS a uniform bicubic B-spline; both sides evaluate it in double
// precision (Bfr from the same control points, our NURBS by de Boor), so only rounding separates them.
constexpr double kExactRelTol = 1e-9;

struct Cage {
  int nu = 0, nv = 0;
  std::vector<Vec3> p;  // grid point (i, j) at i + nu * j
  const Vec3& at(int i, int j) const { return p[std::size_t(i + nu * j)]; }
};

// A deterministic bumpy cage over an uneven grid: a genuinely freeform test surface.
Cage bumpyCage(int nu, int nv) {
  Cage c{nu, nv, {}};
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> jitter(-3.0, 3.0), height(-8.0, 8.0);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) c.p.emplace_back(20.0 * i + jitter(rng), 15.0 * j + jitter(rng), height(rng));
  return c;
}

struct ObjOptions {
  std::vector<int> order;  // OBJ position of grid vertex k (a permutation); identity when empty
  bool rotate_faces = false;
  bool shuffle_faces = false;
};

std::string objText(const Cage& c, const ObjOptions& o = {}) {
  const int n = c.nu * c.nv;
  std::vector<int> order = o.order;
  if (order.empty())
    for (int k = 0; k < n; ++k) order.push_back(k);
  std::vector<int> grid_of_obj(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) grid_of_obj[std::size_t(order[std::size_t(k)])] = k;
  std::ostringstream os;
  os.precision(17);
  os << "# test cage\n";
  for (int k = 0; k < n; ++k) {
    const Vec3& p = c.p[std::size_t(grid_of_obj[std::size_t(k)])];
    os << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  }
  std::vector<std::array<int, 4>> faces;
  for (int j = 0; j + 1 < c.nv; ++j)
    for (int i = 0; i + 1 < c.nu; ++i) {
      const int g[4] = {i + c.nu * j, i + 1 + c.nu * j, i + 1 + c.nu * (j + 1), i + c.nu * (j + 1)};
      const int r = o.rotate_faces ? (i + 2 * j) % 4 : 0;
      std::array<int, 4> f{};
      for (int k = 0; k < 4; ++k) f[std::size_t(k)] = order[std::size_t(g[(k + r) % 4])] + 1;
      faces.push_back(f);
    }
  if (o.shuffle_faces) std::shuffle(faces.begin(), faces.end(), std::mt19937(7));
  for (const auto& f : faces) os << "f " << f[0] << "/1/1 " << f[1] << "//2 " << f[2] << ' ' << f[3] << '\n';
  return os.str();
}

class SubdivisionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pvrr_subdivision_test_" +
                                        std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  fs::path dir_;
};

// The uniform bicubic B-spline with control net `net` (nu x nv) and knots 0, 1, 2, ...: its domain is
// [3, nu] x [3, nv].
NurbsSurface uniformBicubic(const Cage& net) {
  NurbsDefinition d;
  d.degree_u = d.degree_v = 3;
  d.count_u = net.nu;
  d.count_v = net.nv;
  for (int k = 0; k < net.nu + 4; ++k) d.knots_u.push_back(k);
  for (int k = 0; k < net.nv + 4; ++k) d.knots_v.push_back(k);
  for (int i = 0; i < net.nu; ++i)
    for (int j = 0; j < net.nv; ++j) d.points.push_back(net.at(i, j));
  return NurbsSurface(d, "uniform bicubic");
}

struct Worst {
  double p = 0, d1 = 0, d2 = 0;
};

// Compares the limit surface at (u, v) with the B-spline at (u + shift, v + shift) over [u0,u1] x [v0,v1].
Worst compare(const Surface& limit, const Surface& spline, double shift, double u0, double u1, double v0, double v1,
              double size) {
  Worst w;
  for (int a = 0; a <= 16; ++a)
    for (int b = 0; b <= 16; ++b) {
      const double u = u0 + (u1 - u0) * a / 16, v = v0 + (v1 - v0) * b / 16;
      const SurfaceDerivs x = limit.evaluate(u, v), y = spline.evaluate(u + shift, v + shift);
      w.p = std::max(w.p, glm::length(x.p - y.p) / size);
      w.d1 = std::max({w.d1, glm::length(x.du - y.du) / size, glm::length(x.dv - y.dv) / size});
      w.d2 = std::max({w.d2, glm::length(x.duu - y.duu) / size, glm::length(x.duv - y.duv) / size,
                       glm::length(x.dvv - y.dvv) / size});
    }
  return w;
}

double cageSize(const Cage& c) {
  Vec3 lo(kInf), hi(-kInf);
  for (const Vec3& p : c.p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return glm::length(hi - lo);
}

TEST_F(SubdivisionTest, InteriorOfARegularCageIsTheUniformBicubicBSpline) {
  const Cage c = bumpyCage(8, 7);
  const SurfacePtr s = loadSubdivisionCage(write("cage.obj", objText(c)));
  const ParamDomain d = s->domain();
  EXPECT_EQ(d.u0, 0.0);
  EXPECT_EQ(d.u1, 7.0);
  EXPECT_EQ(d.v0, 0.0);
  EXPECT_EQ(d.v1, 6.0);
  // Faces not touching the boundary: u in [1, 6], v in [1, 5]; face a has B-spline span [a + 2, a + 3].
  const Worst w = compare(*s, uniformBicubic(c), 2.0, 1.0, 6.0, 1.0, 5.0, cageSize(c));
  EXPECT_LT(w.p, kExactRelTol);
  EXPECT_LT(w.d1, kExactRelTol);
  EXPECT_LT(w.d2, kExactRelTol);
  // Normals along du x dv follow the faces' counter-clockwise winding seen from +z.
  EXPECT_GT(s->normal(3.5, 3.5).z, 0.0);
  std::cout << "[ measured ] interior: position " << w.p << ", first " << w.d1 << ", second " << w.d2
            << " (relative)\n";
}

TEST_F(SubdivisionTest, BoundaryFacesFollowTheEdgeAndCornerRule) {
  // With boundary edges and corners interpolated, a regular boundary patch is the B-spline whose missing
  // control points are reflected through the boundary: P(-1) = 2 P(0) - P(1) along each direction (and at a
  // corner the tensor product of both reflections). The whole domain is then one B-spline.
  const Cage c = bumpyCage(6, 5);
  Cage ext{c.nu + 2, c.nv + 2, {}};
  auto get = [&](int i, int j) -> Vec3 {
    // Reflected index access: i = -1 -> 2 P(0) - P(1), i = nu -> 2 P(nu-1) - P(nu-2).
    auto refl = [](int k, int n, int& a, int& b) {
      if (k < 0) { a = 0; b = 1; return true; }
      if (k >= n) { a = n - 1; b = n - 2; return true; }
      a = k; b = k;
      return false;
    };
    int ia, ib, ja, jb;
    const bool ri = refl(i, c.nu, ia, ib), rj = refl(j, c.nv, ja, jb);
    auto row = [&](int jj) { return ri ? 2.0 * c.at(ia, jj) - c.at(ib, jj) : c.at(ia, jj); };
    return rj ? 2.0 * row(ja) - row(jb) : row(ja);
  };
  for (int j = -1; j <= c.nv; ++j)
    for (int i = -1; i <= c.nu; ++i) ext.p.push_back(get(i, j));
  const SurfacePtr s = loadSubdivisionCage(write("cage.obj", objText(c)));
  // Face a of the cage is span [a + 3, a + 4] of the extended B-spline.
  const Worst w = compare(*s, uniformBicubic(ext), 3.0, 0.0, c.nu - 1.0, 0.0, c.nv - 1.0, cageSize(c));
  EXPECT_LT(w.p, kExactRelTol);
  EXPECT_LT(w.d1, kExactRelTol);
  EXPECT_LT(w.d2, kExactRelTol);
  // Corners are interpolated.
  EXPECT_LT(glm::length(s->evaluate(0, 0).p - c.at(0, 0)), kExactRelTol * cageSize(c));
  EXPECT_LT(glm::length(s->evaluate(c.nu - 1, c.nv - 1).p - c.at(c.nu - 1, c.nv - 1)), kExactRelTol * cageSize(c));
  std::cout << "[ measured ] whole domain incl. boundary: position " << w.p << ", first " << w.d1 << ", second "
            << w.d2 << " (relative)\n";
}

TEST_F(SubdivisionTest, GridIsFoundFromTopologyNotFromVertexOrFaceOrder) {
  const Cage c = bumpyCage(6, 5);
  const SurfacePtr plain = loadSubdivisionCage(write("plain.obj", objText(c)));
  // Scrambled vertex order (grid vertex 0 keeps the lowest index, so the origin corner is the same), faces
  // starting at different corners, faces shuffled, OBJ "v/vt/vn" index forms.
  ObjOptions o;
  const int n = c.nu * c.nv;
  o.order.push_back(0);
  std::vector<int> rest;
  for (int k = 1; k < n; ++k) rest.push_back(k);
  std::shuffle(rest.begin(), rest.end(), std::mt19937(99));
  o.order.insert(o.order.end(), rest.begin(), rest.end());
  o.rotate_faces = true;
  o.shuffle_faces = true;
  const SurfacePtr scrambled = loadSubdivisionCage(write("scrambled.obj", objText(c, o)));
  const Worst w = compare(*plain, *scrambled, 0.0, 0.0, c.nu - 1.0, 0.0, c.nv - 1.0, cageSize(c));
  EXPECT_LT(w.p, kExactRelTol);
  EXPECT_LT(w.d1, kExactRelTol);
}

void expectCageError(const std::string& path, const std::string& what) {
  try {
    loadSubdivisionCage(path);
    ADD_FAILURE() << path << ": expected pvrr::Error (" << what << ")";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST_F(SubdivisionTest, NonGridCagesAreRejectedWithAClearError) {
  expectCageError((dir_ / "missing.obj").string(), "cannot open");
  expectCageError(write("empty.obj", "# nothing\n"), "no faces");
  expectCageError(write("triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "quads");
  expectCageError(write("badindex.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 9\n"), "out of range");
  expectCageError(write("badvertex.obj", "v 0 0 zero\n"), "expected \"v x y z\"");
  // A cube: every vertex has valence 3 (extraordinary), no corner exists.
  expectCageError(write("cube.obj",
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"),
                  "corner");
  // An L of three quads: valid manifold quads, not a rectangle.
  expectCageError(write("ell.obj",
                        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 0 2 0\nv 1 2 0\n"
                        "f 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\n"),
                  "rectangular grid");
  // A 3x3-vertex grid with one face wound the other way.
  expectCageError(write("winding.obj",
                        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 0 2 0\nv 1 2 0\nv 2 2 0\n"
                        "f 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\nf 5 8 9 6\n"),
                  "same direction");
  // Two separate quads.
  expectCageError(write("apart.obj",
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 6 1 0\nv 5 1 0\n"
                        "f 1 2 3 4\nf 5 6 7 8\n"),
                  "not connected");
  // A vertex no face uses.
  expectCageError(write("unused.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 9 9 9\nf 1 2 3 4\n"), "used by no face");
  // A vertex with five quads around it (a 3x3 grid's centre vertex is regular; this star is not).
  std::ostringstream star;
  star << "v 0 0 0\n";
  for (int k = 0; k < 10; ++k) {
    const double a = 2 * kPi * k / 10, r = k % 2 ? 1.0 : 2.0;
    star << "v " << r * std::cos(a) << ' ' << r * std::sin(a) << " 0\n";
  }
  for (int k = 0; k < 5; ++k) star << "f 1 " << 2 + 2 * k << ' ' << 2 + (2 * k + 1) % 10 << ' ' << 2 + (2 * k + 2) % 10 << '\n';
  expectCageError(write("star.obj", star.str()), "grid");
}

TEST_F(SubdivisionTest, ShippedFreeformCageLoadsAndMatchesItsClosedForm) {
  using D = FreeformCageDesign;
  const std::string path = std::string(PVRR_SOURCE_DIR) + "/models/freeform-mirror-cage.obj";
  const SurfacePtr s = loadSubdivisionCage(path);
  const ParamDomain d = s->domain();
  EXPECT_EQ(d.u1, D::nx - 1.0);
  EXPECT_EQ(d.v1, D::ny - 1.0);
  // On interior faces the limit of a quadratic sampled on a uniform grid (spacing h) is the quadratic
  // raised by h^2/3 in each squared term (the cubic B-spline of t^2 at unit knots is t^2 + 1/3), and x, y
  // are linear in u, v.
  const double hx = D::width_mm / (D::nx - 1), hy = D::height_mm / (D::ny - 1);
  double worst = 0;
  for (int a = 0; a <= 12; ++a)
    for (int b = 0; b <= 12; ++b) {
      const double u = 1 + (D::nx - 3.0) * a / 12, v = 1 + (D::ny - 3.0) * b / 12;
      const SurfaceDerivs e = s->evaluate(u, v);
      const double x = -0.5 * D::width_mm + hx * u, y = -0.5 * D::height_mm + hy * v;
      const Vec3 expected(x, y,
                          (x * x + hx * hx / 3) / (2 * D::radius_x_mm) - (y * y + hy * hy / 3) / (2 * D::radius_y_mm));
      worst = std::max(worst, glm::length(e.p - expected));
      EXPECT_NEAR(e.duu.z, hx * hx / D::radius_x_mm, 1e-9);
      EXPECT_NEAR(e.dvv.z, -hy * hy / D::radius_y_mm, 1e-9);
      EXPECT_NEAR(e.duv.z, 0.0, 1e-9);
    }
  EXPECT_LT(worst, kExactRelTol * D::width_mm);
  // Saddle at the centre: the normal is +z; bending towards +z along x (concave there, curvature -1/1500)
  // and away from it along y (convex, +1/900), in surface.h's sign convention.
  const double uc = 0.5 * (D::nx - 1), vc = 0.5 * (D::ny - 1);
  EXPECT_LT(angleBetween(s->normal(uc, vc), Vec3(0, 0, 1)), 1e-12);
  const Curvature k = s->curvature(uc, vc);
  EXPECT_NEAR(k.k1, 1 / D::radius_y_mm, 1e-12);
  EXPECT_NEAR(k.k2, -1 / D::radius_x_mm, 1e-12);
  // The shipped file is what the generator writes.
  const std::string again = (dir_ / "freeform-mirror-cage.obj").string();
  writeFreeformCageObj(again);
  auto slurp = [](const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  EXPECT_TRUE(slurp(again) == slurp(path)) << "models/freeform-mirror-cage.obj is out of date";
}

}  // namespace
}  // namespace pvrr::cad

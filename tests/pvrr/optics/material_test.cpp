// Tests of pvrr/optics/material.h: dispersion models against catalogue values, the material library, mirror metals.
#include "pvrr/optics/material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr {
namespace {

// Schott prints n to 5 decimals; half a unit of the last place plus the same again for the Sellmeier fit.
constexpr double kCatalogueIndexTol = 5e-5;
// Schott prints V_d to 2 decimals.
constexpr double kCatalogueAbbeTol = 0.02;
// A closed-form identity of the model evaluated with a few double operations (n ~ 1.5).
constexpr double kExactTol = 1e-12;
// V_d = (n_d - 1)/(n_F - n_C) divides by ~0.01, amplifying the 1e-16 rounding of n to ~1e-12 relative.
constexpr double kExactAbbeTol = 1e-9;

TEST(Material, Bk7SellmeierMatchesSchottDataSheet) {
  const LensMaterial m = lookupLensMaterial("n-bk7");
  EXPECT_EQ(m.dispersion.kind(), Dispersion::Kind::Sellmeier);
  const Dispersion& d = m.dispersion;
  EXPECT_NEAR(d.n_d(), 1.51680, kCatalogueIndexTol);
  EXPECT_NEAR(d.index(kLineF_nm), 1.52238, kCatalogueIndexTol);
  EXPECT_NEAR(d.index(kLineC_nm), 1.51432, kCatalogueIndexTol);
  EXPECT_NEAR(d.abbe(), 64.17, kCatalogueAbbeTol);
  // Independent evaluation of the Sellmeier sum at the d line (coefficients from optics-facts.md).
  const double l2 = std::pow(kLineD_nm * 1e-3, 2);
  const double n2 = 1 + 1.03961212 * l2 / (l2 - 0.00600069867) + 0.231792344 * l2 / (l2 - 0.0200179144) +
                    1.01046945 * l2 / (l2 - 103.560653);
  EXPECT_NEAR(d.n_d(), std::sqrt(n2), kExactTol);
}

TEST(Material, AbbeModelReproducesNdAndAbbeNumberExactly) {
  for (double n_d : {1.0, 1.498, 1.5168, 1.74, 2.0}) {
    for (double V : {20.0, 33.0, 58.0, 64.17, 90.0}) {
      const Dispersion d = Dispersion::fromAbbe(n_d, V);
      EXPECT_EQ(d.kind(), Dispersion::Kind::Abbe);
      EXPECT_NEAR(d.index(kLineD_nm), n_d, kExactTol);
      EXPECT_NEAR(d.index(kLineF_nm) - d.index(kLineC_nm), (n_d - 1.0) / V, kExactTol);
      if (n_d > 1) {
        EXPECT_NEAR(d.abbe(), V, kExactAbbeTol * V);
      }
      // It is the Cauchy law A + B / lambda^2.
      for (double l : {400.0, 500.0, 700.0})
        EXPECT_NEAR(d.index(l), d.cauchyA() + d.cauchyB_nm2() / (l * l), kExactTol);
    }
  }
}

// The often-quoted form n_d + (n_d - 1)/V_d (523655/lambda^2 - 1.5168) (three-gpu-pathtracer, dspbr-pt) is the
// same law with rounded constants: agreement to about 1e-6 over the visible.
TEST(Material, AbbeModelAgreesWithPublishedCauchyConstants) {
  // (n_d - 1)/V_d <= 0.03 times the constants' rounding (8 nm^2 in 523663, 6e-5 in 1.5168): < 2e-6.
  constexpr double kRoundedConstantsTol = 2e-6;
  for (const std::string& name : lensMaterialNames()) {
    const Dispersion d = lookupLensMaterial(name).dispersion;
    if (d.kind() != Dispersion::Kind::Abbe) continue;
    const double n_d = d.n_d(), V = d.abbe();
    for (double l = 400; l <= 700; l += 10)
      EXPECT_NEAR(d.index(l), n_d + (n_d - 1) / V * (523655.0 / (l * l) - 1.5168), kRoundedConstantsTol)
          << name << " at " << l << " nm";
  }
}

TEST(Material, NamedSpectacleMaterialsMatchOpticsFacts) {
  struct Fact {
    const char* name;
    double n_d, V_d;
  };
  // optics-facts.md, "Spectacle-lens materials".
  const Fact facts[] = {{"cr39", 1.498, 58},          {"trivex", 1.532, 44},          {"mid-index-1.56", 1.56, 37},
                        {"polycarbonate", 1.586, 30}, {"high-index-1.60", 1.60, 41}, {"high-index-1.67", 1.67, 32},
                        {"high-index-1.74", 1.74, 33}, {"n-bk7", 1.5168, 64.17}};
  EXPECT_EQ(lensMaterialNames().size(), std::size(facts));
  for (const Fact& f : facts) {
    const LensMaterial m = lookupLensMaterial(f.name);
    EXPECT_EQ(m.name, f.name);
    EXPECT_FALSE(m.description.empty());
    const bool sellmeier = m.dispersion.kind() == Dispersion::Kind::Sellmeier;
    EXPECT_NEAR(m.dispersion.n_d(), f.n_d, sellmeier ? kCatalogueIndexTol : kExactTol) << f.name;
    EXPECT_NEAR(m.dispersion.abbe(), f.V_d, sellmeier ? kCatalogueAbbeTol : kExactAbbeTol * f.V_d) << f.name;
    // Normal dispersion: the index falls with wavelength over the visible.
    for (double l = 400; l < 700; l += 10)
      EXPECT_GT(m.dispersion.index(l), m.dispersion.index(l + 10)) << f.name << " at " << l << " nm";
  }
}

TEST(Material, LookupIsCaseInsensitiveAndUnknownNamesListTheKnownOnes) {
  EXPECT_EQ(lookupLensMaterial("PolyCarbonate").name, "polycarbonate");
  EXPECT_EQ(lookupLensMaterial("N-BK7").name, "n-bk7");
  try {
    lookupLensMaterial("unobtainium");
    FAIL() << "expected pvrr::Error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unobtainium"), std::string::npos) << msg;
    for (const std::string& n : lensMaterialNames()) EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
  try {
    lookupMetal("gold");
    FAIL() << "expected pvrr::Error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const std::string& n : metalNames()) EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
}

TEST(Material, ConstantDispersionAndInvalidInput) {
  const Dispersion c = Dispersion::constant(1.6);
  EXPECT_EQ(c.index(400), 1.6);
  EXPECT_EQ(c.index(700), 1.6);
  EXPECT_TRUE(std::isinf(c.abbe()));
  EXPECT_EQ(Dispersion().index(kLineD_nm), 1.5);  // documented default
  EXPECT_THROW(Dispersion::constant(0.9), Error);
  EXPECT_THROW(Dispersion::constant(std::nan("")), Error);
  EXPECT_THROW(Dispersion::fromAbbe(0.5, 40), Error);
  EXPECT_THROW(Dispersion::fromAbbe(1.5, 0), Error);
  EXPECT_THROW(Dispersion::fromAbbe(1.5, -3), Error);
  // n_d = 1 with strong dispersion would go below 1 in the red.
  EXPECT_THROW(Dispersion::fromAbbe(1.0001, 0.001), Error);
  // A Sellmeier pole (C = 0.25 um^2 -> 500 nm) inside the visible.
  EXPECT_THROW(Dispersion::sellmeier({1.0, 0.0, 0.0}, {0.25, 0.0, 0.0}), Error);
}

// Textbook normal-incidence reflectance of fresh evaporated films in the visible (Bass, Handbook of Optics;
// Palik): Ag 0.95..0.98, Al 0.90..0.92, Cr 0.55..0.65. The cited data sit at the edges of these ranges, so
// the bounds are widened there: Johnson & Christy's silver films reach 0.99 in the red, Rakic's aluminium
// 0.922 in the blue, and Johnson & Christy's chromium gives 0.551..0.559 (its bottom edge, 0.54 leaves room).
TEST(Material, MetalNormalReflectanceInTextbookRange) {
  struct Range {
    const char* name;
    double lo, hi;
  };
  for (const Range r : {Range{"silver", 0.95, 0.995}, Range{"aluminium", 0.90, 0.925}, Range{"chromium", 0.54, 0.65}}) {
    const Metal m = lookupMetal(r.name);
    EXPECT_FALSE(m.source().empty());
    for (double l : {450.0, 550.0, 650.0, kRgbWavelengths_nm[0], kRgbWavelengths_nm[1], kRgbWavelengths_nm[2]}) {
      const double R = m.normalReflectance(l);
      EXPECT_GE(R, r.lo) << r.name << " at " << l << " nm";
      EXPECT_LE(R, r.hi) << r.name << " at " << l << " nm";
      const ComplexIndex c = m.index(l);
      EXPECT_NEAR(R, (std::pow(c.n - 1, 2) + c.k * c.k) / (std::pow(c.n + 1, 2) + c.k * c.k), kExactTol);
    }
  }
}

TEST(Material, MetalTablesInterpolateAndCoverTheSpectralRange) {
  for (const std::string& name : metalNames()) {
    const Metal m = lookupMetal(name);
    EXPECT_LE(m.minWavelength_nm(), kSpectralMin_nm) << name;
    EXPECT_GE(m.maxWavelength_nm(), kSpectralMax_nm) << name;
    EXPECT_THROW(m.index(m.minWavelength_nm() - 1), Error);
    EXPECT_THROW(m.index(m.maxWavelength_nm() + 1), Error);
    const Vec3 n = m.n_rgb(), k = m.k_rgb();
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(n[c], m.index(kRgbWavelengths_nm[c]).n);
      EXPECT_EQ(k[c], m.index(kRgbWavelengths_nm[c]).k);
      EXPECT_GT(k[c], 0.0);
    }
    // Linear interpolation: the midpoint of two nearby wavelengths is the mean of their values when both lie
    // in one table interval (1 nm apart, off the table nodes).
    const ComplexIndex a = m.index(550.2), b = m.index(551.2), mid = m.index(550.7);
    EXPECT_NEAR(mid.n, 0.5 * (a.n + b.n), kExactTol);
    EXPECT_NEAR(mid.k, 0.5 * (a.k + b.k), kExactTol);
  }
  // Published table values are reproduced at the nodes (Johnson & Christy 1972, Ag at 548.6 nm).
  const ComplexIndex ag = lookupMetal("silver").index(548.6);
  EXPECT_NEAR(ag.n, 0.06, kExactTol);
  EXPECT_NEAR(ag.k, 3.586, kExactTol);
  EXPECT_EQ(lookupMetal("Aluminum").name(), "aluminium");
}

}  // namespace
}  // namespace pvrr

#include "pvrr/optics/material.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <sstream>
#include <utility>

#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr {

namespace {

// Step of the validation scan over [kDispersionCheckMin_nm, kDispersionCheckMax_nm].
constexpr double kCheckStep_nm = 5.0;

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string joinNames(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

double sellmeierIndex(const std::array<double, 3>& B, const std::array<double, 3>& C_um2, double lambda_nm) {
  const double l_um = lambda_nm * 1e-3;
  const double l2 = l_um * l_um;
  double n2 = 1.0;
  for (int i = 0; i < 3; ++i) n2 += B[size_t(i)] * l2 / (l2 - C_um2[size_t(i)]);
  return n2 > 0 ? std::sqrt(n2) : std::nan("");
}

// Throws unless d gives a finite index >= 1 over the check range.
void validateOverVisible(const Dispersion& d, const std::string& what) {
  for (double l = kDispersionCheckMin_nm; l <= kDispersionCheckMax_nm + 1e-9; l += kCheckStep_nm) {
    const double n = d.index(l);
    if (!std::isfinite(n) || n < 1.0)
      throw Error(what + ": gives n = " + fmt(n) + " at " + fmt(l) + " nm; expected a real index >= 1 over " +
                  fmt(kDispersionCheckMin_nm) + ".." + fmt(kDispersionCheckMax_nm) + " nm");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------- Dispersion

Dispersion Dispersion::constant(double n) {
  if (!std::isfinite(n) || n < 1.0) throw Error("constant refractive index: expected a number >= 1, got " + fmt(n));
  Dispersion d;
  d.kind_ = Kind::Constant;
  d.n_d_ = n;
  return d;
}

Dispersion Dispersion::sellmeier(const std::array<double, 3>& B, const std::array<double, 3>& C_um2) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(B[size_t(i)]) || !std::isfinite(C_um2[size_t(i)]))
      throw Error("Sellmeier coefficients: expected finite B1..B3 and C1..C3 (um^2), got B" + std::to_string(i + 1) +
                  " = " + fmt(B[size_t(i)]) + ", C" + std::to_string(i + 1) + " = " + fmt(C_um2[size_t(i)]));
  Dispersion d;
  d.kind_ = Kind::Sellmeier;
  d.B_ = B;
  d.C_um2_ = C_um2;
  d.n_d_ = std::nan("");
  validateOverVisible(d, "Sellmeier coefficients " + d.describe());
  return d;
}

Dispersion Dispersion::fromAbbe(double n_d, double V_d) {
  if (!std::isfinite(n_d) || n_d < 1.0) throw Error("n_d: expected a number >= 1, got " + fmt(n_d));
  if (!std::isfinite(V_d) || V_d <= 0) throw Error("Abbe number V_d: expected a number > 0, got " + fmt(V_d));
  Dispersion d;
  d.kind_ = Kind::Abbe;
  d.n_d_ = n_d;
  d.v_d_ = V_d;
  const double inv_span_nm2 = 1.0 / (kLineF_nm * kLineF_nm) - 1.0 / (kLineC_nm * kLineC_nm);
  d.cauchy_b_nm2_ = (n_d - 1.0) / V_d / inv_span_nm2;
  validateOverVisible(d, "Abbe dispersion " + d.describe());
  return d;
}

double Dispersion::index(double lambda_nm) const {
  PVRR_CHECK(lambda_nm > 0 && std::isfinite(lambda_nm), << "lambda_nm = " << lambda_nm);
  switch (kind_) {
    case Kind::Constant:
      return n_d_;
    case Kind::Abbe:
      // Written relative to the d line so that index(kLineD_nm) returns n_d without rounding.
      return n_d_ + cauchy_b_nm2_ * (1.0 / (lambda_nm * lambda_nm) - 1.0 / (kLineD_nm * kLineD_nm));
    case Kind::Sellmeier:
      return sellmeierIndex(B_, C_um2_, lambda_nm);
  }
  return std::nan("");
}

double Dispersion::abbe() const {
  if (kind_ == Kind::Constant) return kInf;
  return (n_d() - 1.0) / (index(kLineF_nm) - index(kLineC_nm));
}

double Dispersion::cauchyA() const {
  switch (kind_) {
    case Kind::Constant:
      return n_d_;
    case Kind::Abbe:
      return n_d_ - cauchy_b_nm2_ / (kLineD_nm * kLineD_nm);
    case Kind::Sellmeier:
      break;
  }
  return std::nan("");
}

double Dispersion::cauchyB_nm2() const {
  switch (kind_) {
    case Kind::Constant:
      return 0;
    case Kind::Abbe:
      return cauchy_b_nm2_;
    case Kind::Sellmeier:
      break;
  }
  return std::nan("");
}

std::string Dispersion::describe() const {
  switch (kind_) {
    case Kind::Constant:
      return "constant n=" + fmt(n_d_);
    case Kind::Abbe:
      return "Abbe n_d=" + fmt(n_d_) + " V_d=" + fmt(v_d_);
    case Kind::Sellmeier:
      return "Sellmeier B=(" + fmt(B_[0]) + ", " + fmt(B_[1]) + ", " + fmt(B_[2]) + ") C=(" + fmt(C_um2_[0]) + ", " +
             fmt(C_um2_[1]) + ", " + fmt(C_um2_[2]) + ") um^2";
  }
  return {};
}

// ------------------------------------------------------------------------------------------ lens materials

namespace {

struct AbbeEntry {
  const char* name;
  const char* description;
  double n_d, V_d;
};

// Nominal spectacle-lens materials, (n_d, V_d) at the helium d line. Vendors differ by about +-2 in V_d.
// Sources: lens-shapers.com knowledge base (lens materials), igateoptics.com material specifications, Jalie,
// lens data (precision-optical.co.uk); collected in /work/shared/notes/optics-facts.md.
constexpr AbbeEntry kAbbeMaterials[] = {
    {"cr39", "CR-39 (allyl diglycol carbonate, 'plastic 1.5')", 1.498, 58},
    {"trivex", "Trivex (urethane-based)", 1.532, 44},
    {"mid-index-1.56", "mid-index plastic 1.56", 1.56, 37},
    {"polycarbonate", "polycarbonate", 1.586, 30},
    {"high-index-1.60", "high-index plastic 1.60 (MR-8 class)", 1.60, 41},
    {"high-index-1.67", "high-index plastic 1.67 (MR-7/MR-10 class)", 1.67, 32},
    {"high-index-1.74", "high-index plastic 1.74 (MR-174 class)", 1.74, 33},
};

// Schott N-BK7 Sellmeier coefficients (lambda in um, C in um^2), Schott optical glass data sheet, as listed by
// refractiveindex.info; they give n_d = 1.51680 and V_d = 64.17.
constexpr std::array<double, 3> kBk7B = {1.03961212, 0.231792344, 1.01046945};
constexpr std::array<double, 3> kBk7C_um2 = {0.00600069867, 0.0200179144, 103.560653};

}  // namespace

std::vector<std::string> lensMaterialNames() {
  std::vector<std::string> names;
  for (const AbbeEntry& e : kAbbeMaterials) names.emplace_back(e.name);
  names.emplace_back("n-bk7");
  return names;
}

LensMaterial lookupLensMaterial(const std::string& name) {
  const std::string key = lower(name);
  for (const AbbeEntry& e : kAbbeMaterials)
    if (key == e.name)
      return {e.name, std::string(e.description) + ", n_d = " + fmt(e.n_d) + ", V_d = " + fmt(e.V_d),
              Dispersion::fromAbbe(e.n_d, e.V_d)};
  if (key == "n-bk7")
    return {"n-bk7", "Schott N-BK7 borosilicate crown glass (Sellmeier, Schott data sheet)",
            Dispersion::sellmeier(kBk7B, kBk7C_um2)};
  throw Error("lens material \"" + name + "\": unknown; expected one of " + joinNames(lensMaterialNames()));
}

// ------------------------------------------------------------------------------------------------- metals

Metal::Metal(std::string name, std::string source, std::vector<Sample> table)
    : name_(std::move(name)), source_(std::move(source)), table_(std::move(table)) {
  PVRR_CHECK(table_.size() >= 2, << name_);
  for (size_t i = 1; i < table_.size(); ++i)
    PVRR_CHECK(table_[i].lambda_nm > table_[i - 1].lambda_nm, << name_ << " sample " << i);
}

ComplexIndex Metal::index(double lambda_nm) const {
  if (!(lambda_nm >= minWavelength_nm() && lambda_nm <= maxWavelength_nm()))
    throw Error("metal \"" + name_ + "\": no optical data at " + fmt(lambda_nm) + " nm; the table covers " +
                fmt(minWavelength_nm()) + ".." + fmt(maxWavelength_nm()) + " nm");
  auto hi = std::lower_bound(table_.begin(), table_.end(), lambda_nm,
                             [](const Sample& s, double l) { return s.lambda_nm < l; });
  if (hi == table_.begin()) return {hi->n, hi->k};
  auto lo = hi - 1;
  const double t = (lambda_nm - lo->lambda_nm) / (hi->lambda_nm - lo->lambda_nm);
  return {lo->n + t * (hi->n - lo->n), lo->k + t * (hi->k - lo->k)};
}

Vec3 Metal::n_rgb() const {
  return {index(kRgbWavelengths_nm[0]).n, index(kRgbWavelengths_nm[1]).n, index(kRgbWavelengths_nm[2]).n};
}

Vec3 Metal::k_rgb() const {
  return {index(kRgbWavelengths_nm[0]).k, index(kRgbWavelengths_nm[1]).k, index(kRgbWavelengths_nm[2]).k};
}

double Metal::normalReflectance(double lambda_nm) const {
  const ComplexIndex c = index(lambda_nm);
  return fresnelConductor(1.0, 1.0, c.n, c.k);
}

namespace {

// Measured optical constants, visible part of each table (wavelength converted from um to nm, values as
// published). All three are taken from the refractiveindex.info database (CC0), which reproduces the papers.
//
// Silver: P. B. Johnson and R. W. Christy, "Optical constants of the noble metals", Phys. Rev. B 6, 4370 (1972).
constexpr Metal::Sample kSilverJohnsonChristy[] = {
    {381.5, 0.05, 1.864}, {397.4, 0.05, 2.070}, {413.3, 0.05, 2.275}, {430.5, 0.04, 2.462}, {450.9, 0.04, 2.657},
    {471.4, 0.05, 2.869}, {495.9, 0.05, 3.093}, {520.9, 0.05, 3.324}, {548.6, 0.06, 3.586}, {582.1, 0.05, 3.858},
    {616.8, 0.06, 4.152}, {659.5, 0.05, 4.483}, {704.5, 0.04, 4.838}, {756.0, 0.03, 5.242},
};

// Aluminium: A. D. Rakic, "Algorithm for the determination of intrinsic optical constants of metal films:
// application to aluminum", Appl. Opt. 34, 4755 (1995) (evaporated films).
constexpr Metal::Sample kAluminiumRakic[] = {
    {364.66, 0.39877, 4.3957}, {413.28, 0.52135, 5.0008}, {442.80, 0.60790, 5.3676}, {476.87, 0.72780, 5.7781},
    {516.60, 0.87340, 6.2418}, {563.57, 1.0728, 6.7839},  {619.93, 1.3660, 7.4052},  {652.25, 1.5724, 7.7354},
    {688.81, 1.8301, 8.0601},  {729.32, 2.1606, 8.3565},
};

// Chromium: P. B. Johnson and R. W. Christy, "Optical constants of transition metals: Ti, V, Cr, Mn, Fe, Co, Ni,
// and Pd", Phys. Rev. B 9, 5056 (1974).
constexpr Metal::Sample kChromiumJohnsonChristy[] = {
    {381.0, 1.92, 2.74}, {397.0, 2.00, 2.83}, {413.0, 2.08, 2.93}, {431.0, 2.19, 3.04}, {451.0, 2.33, 3.14},
    {471.0, 2.51, 3.24}, {496.0, 2.75, 3.30}, {521.0, 2.94, 3.33}, {549.0, 3.18, 3.33}, {582.0, 3.22, 3.30},
    {617.0, 3.17, 3.30}, {659.0, 3.09, 3.34}, {704.0, 3.05, 3.39}, {756.0, 3.08, 3.42},
};

}  // namespace

std::vector<std::string> metalNames() { return {"silver", "aluminium", "chromium"}; }

Metal lookupMetal(const std::string& name) {
  const std::string key = lower(name);
  if (key == "silver")
    return Metal("silver", "Johnson & Christy, Phys. Rev. B 6, 4370 (1972)",
                 {std::begin(kSilverJohnsonChristy), std::end(kSilverJohnsonChristy)});
  if (key == "aluminium" || key == "aluminum")
    return Metal("aluminium", "Rakic, Appl. Opt. 34, 4755 (1995)",
                 {std::begin(kAluminiumRakic), std::end(kAluminiumRakic)});
  if (key == "chromium")
    return Metal("chromium", "Johnson & Christy, Phys. Rev. B 9, 5056 (1974)",
                 {std::begin(kChromiumJohnsonChristy), std::end(kChromiumJohnsonChristy)});
  throw Error("mirror metal \"" + name + "\": unknown; expected one of " + joinNames(metalNames()));
}

Vec3 absorptionFromInternalTransmittance(const Vec3& tau_i, double thickness_m) {
  if (!(thickness_m > 0) || !std::isfinite(thickness_m))
    throw Error("internal transmittance: the reference thickness must be a finite length > 0, got " +
                std::to_string(thickness_m));
  Vec3 alpha(0.0);
  for (int c = 0; c < 3; ++c) {
    if (!(tau_i[c] > 0 && tau_i[c] <= 1))
      throw Error("internal transmittance: expected each channel in (0, 1], got " + std::to_string(tau_i[c]));
    alpha[c] = tau_i[c] == 1 ? 0.0 : -std::log(tau_i[c]) / thickness_m;
  }
  return alpha;
}

Vec3 internalTransmittance(const Vec3& absorption_per_m, double length_m) {
  if (absorption_per_m == Vec3(0.0)) return Vec3(1.0);
  return glm::exp(-absorption_per_m * length_m);
}

}  // namespace pvrr

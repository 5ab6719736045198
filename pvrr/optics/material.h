// Optical materials: dispersion models for lens dielectrics and tabulated complex indices for mirror metals.
//
// Units: wavelengths in nanometres in vacuum (lambda_nm) everywhere in the interface; Sellmeier coefficients C_i
// in square micrometres as glass catalogues give them. Indices follow pvrr/optics/optics.h (real >= 1 for dielectrics,
// n + i k with k >= 0 for metals).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr {

// The standard spectral lines of the Abbe number (wavelengths in air as catalogues tabulate them, nm).
constexpr double kLineD_nm = 587.5618;  // helium d line: the reference wavelength of n_d
constexpr double kLineF_nm = 486.1327;  // hydrogen F line (blue)
constexpr double kLineC_nm = 656.2725;  // hydrogen C line (red)

// The wavelength range over which every dispersion model is validated when it is built.
constexpr double kDispersionCheckMin_nm = 380.0;
constexpr double kDispersionCheckMax_nm = 780.0;

// The refractive index of a dielectric as a function of wavelength. One of:
//  - constant:  n(lambda) = n (no dispersion; abbe() is +infinity);
//  - Sellmeier: n^2(lambda) - 1 = sum_i B_i lambda^2 / (lambda^2 - C_i), lambda in um, C_i in um^2;
//  - Abbe:      a two-term Cauchy law n(lambda) = A + B / lambda^2 through the catalogue pair (n_d, V_d):
//               B = (n_d - 1) / V_d / (1/lambda_F^2 - 1/lambda_C^2),  A = n_d - B / lambda_d^2,
//               so that n(lambda_d) = n_d and n_F - n_C = (n_d - 1) / V_d exactly.
//    The constants in the often-quoted form n_d + (n_d - 1)/V_d * (523655/lambda^2 - 1.5168) (three-gpu-
//    pathtracer, dspbr-pt) are rounded: 1/(1/lambda_F^2 - 1/lambda_C^2) = 523663.1 nm^2 with the lines above,
//    and 523655 / lambda_d^2 = 1.516834, not 1.5168. The difference in n is below 1e-6 over 400..700 nm, but
//    the form above reproduces n_d and the Abbe number exactly, so that is the one used.
// Default-constructed: constant n = 1.5 (a nominal crown glass).
class Dispersion {
 public:
  enum class Kind { Constant, Sellmeier, Abbe };

  Dispersion() = default;

  // Throws pvrr::Error unless n is finite and >= 1.
  static Dispersion constant(double n);
  // Throws pvrr::Error unless the coefficients give a finite real index >= 1 over kDispersionCheck*_nm.
  static Dispersion sellmeier(const std::array<double, 3>& B, const std::array<double, 3>& C_um2);
  // Throws pvrr::Error unless n_d is finite and >= 1 and V_d is finite and > 0, and the resulting index is
  // >= 1 over kDispersionCheck*_nm.
  static Dispersion fromAbbe(double n_d, double V_d);

  Kind kind() const { return kind_; }
  // n at vacuum wavelength lambda_nm (> 0).
  double index(double lambda_nm) const;
  double n_d() const { return index(kLineD_nm); }
  // Abbe number V_d = (n_d - 1) / (n_F - n_C); +infinity for a constant index.
  double abbe() const;

  // Abbe kind: n(lambda) = n_d + cauchyB_nm2() * (1/lambda^2 - 1/lambda_d^2) = cauchyA() + cauchyB_nm2()/lambda^2.
  // Constant kind: A = n, B = 0. Sellmeier kind: not a Cauchy law; both are NaN.
  double cauchyA() const;
  double cauchyB_nm2() const;
  // Sellmeier kind: the coefficients (zeros otherwise).
  const std::array<double, 3>& sellmeierB() const { return B_; }
  const std::array<double, 3>& sellmeierC_um2() const { return C_um2_; }

  // A one-line description, e.g. "Abbe n_d=1.586 V_d=30" or "Sellmeier B=(...) C=(...) um^2".
  std::string describe() const;

 private:
  Kind kind_ = Kind::Constant;
  double n_d_ = 1.5;         // constant and Abbe kinds
  double cauchy_b_nm2_ = 0;  // Abbe kind
  double v_d_ = kInf;        // Abbe kind: the V_d it was built from
  std::array<double, 3> B_{}, C_um2_{};
};

// Absorption in the glass (a tinted lens, a coloured filter glass). Glass catalogues quote the internal
// transmittance tau_i: the fraction of light that survives a path of a reference thickness inside the glass,
// the interfaces' Fresnel losses excluded (Schott quotes tau_i at 10 mm). By the Beer-Lambert law a path of
// length L keeps exp(-alpha L) with the absorption coefficient alpha = -ln(tau_i) / thickness.
// Per RGB channel; alpha in 1/metre (scene lengths are stored in metres).
constexpr double kInternalTransmittanceThickness_m = 0.010;  // the catalogues' reference path, 10 mm
// alpha (1/m) per channel from tau_i in (0, 1] per channel over thickness_m (> 0). Throws pvrr::Error otherwise.
Vec3 absorptionFromInternalTransmittance(const Vec3& tau_i, double thickness_m = kInternalTransmittanceThickness_m);
// exp(-alpha L) per channel: what a path of length_m inside the glass keeps. Exactly (1, 1, 1) for alpha = 0.
Vec3 internalTransmittance(const Vec3& absorption_per_m, double length_m);

// A named lens material of the library.
struct LensMaterial {
  std::string name;         // the lookup key, e.g. "polycarbonate"
  std::string description;  // human-readable, with the data source
  Dispersion dispersion;
  // Absorption coefficient per channel, 1/m (absorptionFromInternalTransmittance). The library's materials
  // are clear glasses: 0; a scene's lens material may set it ("internal_transmittance", docs/scene-format.md).
  Vec3 absorption_per_m{0.0};
};

// The library of spectacle and optical-glass materials. Names (case-insensitive): "cr39", "trivex",
// "mid-index-1.56", "polycarbonate", "high-index-1.60", "high-index-1.67", "high-index-1.74" (nominal (n_d, V_d)
// of the spectacle industry, sources in material.cpp), and "n-bk7" (Schott Sellmeier coefficients).
// Throws pvrr::Error for an unknown name, listing the known names.
LensMaterial lookupLensMaterial(const std::string& name);
std::vector<std::string> lensMaterialNames();

// Complex refractive index n + i k of an absorbing medium (k >= 0).
struct ComplexIndex {
  double n = 1;
  double k = 0;
};

// A mirror metal: measured (n, k) tabulated against wavelength, interpolated linearly in wavelength.
class Metal {
 public:
  struct Sample {
    double lambda_nm;
    double n, k;
  };
  Metal(std::string name, std::string source, std::vector<Sample> table);

  const std::string& name() const { return name_; }
  const std::string& source() const { return source_; }  // citation of the measured data
  double minWavelength_nm() const { return table_.front().lambda_nm; }
  double maxWavelength_nm() const { return table_.back().lambda_nm; }
  // (n, k) at lambda_nm; throws pvrr::Error outside [minWavelength_nm(), maxWavelength_nm()].
  ComplexIndex index(double lambda_nm) const;
  // n and k at the RGB mode's wavelengths kRgbWavelengths_nm (pvrr/optics/spectrum.h), as (R, G, B).
  Vec3 n_rgb() const;
  Vec3 k_rgb() const;
  // Reflectance at normal incidence from air, ((n-1)^2 + k^2) / ((n+1)^2 + k^2), at lambda_nm.
  double normalReflectance(double lambda_nm) const;

 private:
  std::string name_, source_;
  std::vector<Sample> table_;  // strictly increasing lambda_nm, at least two samples
};

// Mirror metals: "silver", "aluminium" (also "aluminum"), "chromium" (the usual coating of car rear-view
// mirrors), case-insensitive. Throws pvrr::Error for an unknown name, listing the known names.
Metal lookupMetal(const std::string& name);
std::vector<std::string> metalNames();

}  // namespace pvrr

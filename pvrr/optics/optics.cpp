// Conventions: pvrr/optics/optics.h (incident direction towards the surface, eta = n_incident / n_transmitted).
#include "pvrr/optics/optics.h"

#include <algorithm>
#include <cmath>
#include <complex>

namespace pvrr {

namespace {

// |cos_i| clamped to [0, 1]: the Fresnel functions accept either sign (convention 3).
double clampCos(double cos_i) { return std::min(1.0, std::abs(cos_i)); }

}  // namespace

Vec3 faceForward(const Vec3& n, const Vec3& d) { return glm::dot(n, d) > 0 ? -n : n; }

Vec3 reflect(const Vec3& d, const Vec3& n) { return d - 2.0 * glm::dot(d, n) * n; }

double cosTransmittedSquared(double cos_i, double n1, double n2) {
  // 1 - eta^2 sin_i^2 rewritten so that the index difference is formed exactly and sin_i^2 = 1 - cos_i^2 is
  // never computed (it loses digits near normal incidence).
  const double a = n1 * cos_i;
  return ((n2 - n1) * (n2 + n1) + a * a) / (n2 * n2);
}

Refraction refract(const Vec3& d, const Vec3& n, double n1, double n2) {
  Refraction r;
  const Vec3 nf = faceForward(n, d);
  const double cos_i = std::min(1.0, std::max(0.0, -glm::dot(d, nf)));
  r.cos_i = cos_i;
  const double cos_t2 = cosTransmittedSquared(cos_i, n1, n2);
  if (cos_t2 < 0) {
    r.tir = true;
    r.cos_t = 0;
    r.direction = d + 2.0 * cos_i * nf;
    return r;
  }
  const double cos_t = std::min(1.0, std::sqrt(cos_t2));
  const double eta = n1 / n2;
  r.cos_t = cos_t;
  // Tangential part eta * (d + cos_i nf) plus normal part -cos_t nf.
  r.direction = eta * d + (eta * cos_i - cos_t) * nf;
  return r;
}

FresnelDielectricTerms fresnelDielectricTerms(double cos_i_in, double n1, double n2) {
  FresnelDielectricTerms f;
  const double cos_i = clampCos(cos_i_in);
  f.cos_i = cos_i;
  if (n1 == n2) {  // no interface; also avoids 0/0 at grazing incidence
    f.cos_t = cos_i;
    return f;
  }
  const double cos_t2 = cosTransmittedSquared(cos_i, n1, n2);
  if (cos_t2 < 0) {
    f.tir = true;
    f.cos_t = 0;
    f.r_s = f.r_p = 1;
    f.t_s = f.t_p = 0;
    f.R_s = f.R_p = f.R = 1;
    return f;
  }
  const double cos_t = std::min(1.0, std::sqrt(cos_t2));
  f.cos_t = cos_t;
  // With n1 != n2 and no TIR, n1 cos_i + n2 cos_t > 0 and n2 cos_i + n1 cos_t > 0 (at grazing incidence
  // cos_t > 0), so no denominator vanishes and all sums are of non-negative terms.
  const double s_den = n1 * cos_i + n2 * cos_t;
  const double p_den = n2 * cos_i + n1 * cos_t;
  f.r_s = (n1 * cos_i - n2 * cos_t) / s_den;
  f.r_p = (n2 * cos_i - n1 * cos_t) / p_den;
  f.t_s = 2.0 * n1 * cos_i / s_den;
  f.t_p = 2.0 * n1 * cos_i / p_den;
  f.R_s = f.r_s * f.r_s;
  f.R_p = f.r_p * f.r_p;
  f.R = 0.5 * (f.R_s + f.R_p);
  return f;
}

double fresnelDielectric(double cos_i, double n1, double n2) { return fresnelDielectricTerms(cos_i, n1, n2).R; }

double fresnelConductor(double cos_i_in, double n_outside, double n, double k) {
  using C = std::complex<double>;
  if (k == 0 && n == n_outside) return 0;  // no interface; avoids 0/0 at grazing incidence
  const double cos_i = clampCos(cos_i_in);
  const double sin2_i = (1.0 - cos_i) * (1.0 + cos_i);
  const C N2(n * n - k * k, 2.0 * n * k);  // (n + i k)^2
  // w = N cos_t = sqrt(N^2 - n_outside^2 sin_i^2). The principal root has Re >= 0 and Im >= 0 when k >= 0: the
  // transmitted wave propagates into and decays inside the metal. For k = 0 and N^2 < n_outside^2 sin_i^2 it is
  // purely imaginary (an evanescent wave), which gives |r| = 1 as total internal reflection does.
  const C w = std::sqrt(N2 - C(n_outside * n_outside * sin2_i, 0.0));
  const C a(n_outside * cos_i, 0.0);
  const C r_s = (a - w) / (a + w);
  // r_p = (N cos_i - n_outside cos_t) / (N cos_i + n_outside cos_t), multiplied through by N.
  const C b = N2 * cos_i;
  const C r_p = (b - n_outside * w) / (b + n_outside * w);
  return 0.5 * (std::norm(r_s) + std::norm(r_p));
}

double normalIncidenceReflectance(double n1, double n2) {
  const double r = (n1 - n2) / (n1 + n2);
  return r * r;
}

double schlick(double cos_i_in, double n1, double n2) {
  const double r0 = normalIncidenceReflectance(n1, n2);
  double c = clampCos(cos_i_in);
  if (n1 > n2) {
    const double cos_t2 = cosTransmittedSquared(c, n1, n2);
    if (cos_t2 < 0) return 1.0;
    c = std::min(1.0, std::sqrt(cos_t2));
  }
  const double m = 1.0 - c;
  const double m2 = m * m;
  return r0 + (1.0 - r0) * m2 * m2 * m;
}

double criticalAngle(double n1, double n2) {
  if (n1 <= n2) return kPi / 2;
  // atan2(sin, cos) of the critical angle: accurate where asin(n2 / n1) is ill-conditioned (n2 / n1 near 1).
  return std::atan2(n2, std::sqrt((n1 - n2) * (n1 + n2)));
}

}  // namespace pvrr

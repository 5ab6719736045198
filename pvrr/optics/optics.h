// Geometric optics at a single interface: reflection, refraction (vector Snell's law), Fresnel.
//
// THE OPTICS CONVENTIONS OF THE PROJECT. They are stated here and nowhere else; other code refers to this header.
//
//  1. Directions are unit vectors. The incident direction `d` points TOWARDS the surface: from the eye (or the
//     previous hit point) to the surface point. This is the papers' V (Kakimoto et al.; Szirmay-Kalos et al.).
//     Reflected and refracted directions point AWAY from the surface.
//  2. Normals are unit vectors. Functions take the GEOMETRIC normal as stored on the surface, whichever way it
//     faces, and orient it themselves where the result depends on it ("face-forward": the oriented normal n_f
//     faces the incident side, dot(d, n_f) <= 0). Each function below says whether it does.
//  3. cos_i = -dot(d, n_f) = |dot(d, n)| in [0, 1] is the cosine of the angle of incidence; cos_t in [0, 1] is
//     the cosine of the angle between the transmitted direction and -n_f. Fresnel functions take cos_i and use
//     its absolute value, so either sign of dot(d, n) may be passed.
//  4. n1 = n_incident is the index of the medium `d` travels in before the surface; n2 = n_transmitted the
//     index on the other side. eta = n_incident / n_transmitted = n1 / n2: entering glass of index n from air,
//     eta = 1/n; leaving it, eta = n. (GLSL/HLSL refract(V, N, eta) uses the same eta but needs N to face
//     against V; refract() here orients the normal itself.)
//  5. Dielectric indices are real numbers >= 1 (air = 1). Metals have the complex index N = n + i k with the
//     extinction coefficient k >= 0; the medium outside a metal has a real index n_outside.
//  6. Fresnel results named R are power (intensity) reflectances in [0, 1]; names in lower case (r_s, t_p) are
//     amplitude coefficients. Sign convention of the amplitudes (Born & Wolf, Hecht):
//        r_s = (n1 cos_i - n2 cos_t) / (n1 cos_i + n2 cos_t)      t_s = 2 n1 cos_i / (n1 cos_i + n2 cos_t)
//        r_p = (n2 cos_i - n1 cos_t) / (n2 cos_i + n1 cos_t)      t_p = 2 n1 cos_i / (n2 cos_i + n1 cos_t)
//     Energy balance: R + (n2 cos_t) / (n1 cos_i) * t^2 = 1 for each polarisation below the critical angle.
//     "Unpolarised" is the mean of the s and p reflectances.
//
// All functions are pure and thread-safe. Inputs outside their domain (non-unit vectors, indices <= 0) are the
// caller's bug; they are not checked here because these functions sit in the innermost tracing loops.
#pragma once
#include "pvrr/base/math.h"

namespace pvrr {

// Returns n or -n, whichever faces against d (dot(result, d) <= 0): the normal on the incident side.
Vec3 faceForward(const Vec3& n, const Vec3& d);

// Mirror reflection of the incident direction d (towards the surface) about the normal n. The result points
// away from the surface and is independent of which way n faces; |result| = |d|.
Vec3 reflect(const Vec3& d, const Vec3& n);

// The outcome of refract().
struct Refraction {
  bool tir = false;    // total internal reflection: no transmitted ray
  Vec3 direction{0};   // unit; the transmitted direction, or the mirror-reflected direction when tir
  double cos_i = 1;    // cosine of the angle of incidence, in [0, 1]
  double cos_t = 1;    // cosine of the angle of refraction, in [0, 1]; 0 when tir
};

// Vector Snell's law at an interface between indices n1 (incident side, where d comes from) and n2. d is the
// unit incident direction (towards the surface); n is the unit geometric normal facing either way: the function
// orients it (face-forward). The transmitted direction satisfies n1 sin_i = n2 sin_t and lies in the plane of
// d and n. Total internal reflection when n1 sin_i > n2; then `direction` is reflect(d, n) and cos_t = 0.
Refraction refract(const Vec3& d, const Vec3& n, double n1, double n2);

// cos_t^2 for a ray with |cos_i| going from n1 into n2, evaluated as ((n2 - n1)(n2 + n1) + (n1 cos_i)^2) / n2^2,
// which has no cancellation when n2 >= n1 and stays accurate at grazing incidence. Negative means TIR.
double cosTransmittedSquared(double cos_i, double n1, double n2);

// Amplitude and power coefficients of the exact Fresnel equations for a dielectric interface (convention 6).
struct FresnelDielectricTerms {
  bool tir = false;            // total internal reflection: R_s = R_p = R = 1, t_s = t_p = 0
  double cos_i = 1, cos_t = 1; // cos_t = 0 when tir
  double r_s = 0, r_p = 0;     // amplitude reflection; under TIR these are complex of modulus 1 and are
                               // returned as 1 (the phase is not represented)
  double t_s = 1, t_p = 1;     // amplitude transmission (field ratio, not power)
  double R_s = 0, R_p = 0;     // power reflectances r^2
  double R = 0;                // unpolarised: (R_s + R_p) / 2
};

// Exact Fresnel terms for light going from index n1 into n2 at incidence cosine |cos_i|.
FresnelDielectricTerms fresnelDielectricTerms(double cos_i, double n1, double n2);

// Exact unpolarised Fresnel reflectance R of a dielectric interface (n1 -> n2) at incidence cosine |cos_i|;
// 1 under total internal reflection. The transmitted power fraction is 1 - R.
double fresnelDielectric(double cos_i, double n1, double n2);

// Exact unpolarised Fresnel reflectance of a conductor with complex index n + i k (k >= 0) seen from a
// dielectric of real index n_outside, at incidence cosine |cos_i|. With k = 0 it equals
// fresnelDielectric(cos_i, n_outside, n), including total internal reflection when n < n_outside.
double fresnelConductor(double cos_i, double n_outside, double n, double k);

// Reflectance at normal incidence, ((n1 - n2) / (n1 + n2))^2.
double normalIncidenceReflectance(double n1, double n2);

// Schlick's approximation R0 + (1 - R0)(1 - c)^5, with c = cos_i when n1 <= n2 and c = cos_t when n1 > n2
// (the cosine on the denser side, which keeps it symmetric), and 1 under TIR. Exact at normal incidence; up to
// about 23 % relative error elsewhere (n = 1.5, near 55 deg). Use only where an approximation is asked for.
double schlick(double cos_i, double n1, double n2);

// Critical angle in radians for light going from n1 into n2: asin(n2 / n1) when n1 > n2. When n1 <= n2 there is
// no total internal reflection and the result is pi/2 (grazing incidence, the limit as n1 -> n2).
double criticalAngle(double n1, double n2);

}  // namespace pvrr

// The accuracy metric: how far a frame's seen points are from the reference tracer's, and how far its colours
// are, over the pixels where the reference sees an optical element. One implementation for `pvrr compare` /
// `pvrr sweep` (app/compare.cpp) and the tests (tests/support/accuracy.h).
//
// Angular error of a pixel (arcminutes): at the reference's element point p of that pixel, the angle between
// the directions p -> reference seen point and p -> the frame's seen point (seenAngle). It is the error of the
// reflected or refracted ray's direction where the eye's ray meets the element, not an angle at the eye.
// Summaries over the finite errors: median, p95 (quantile), max.
//
// Pixels where the reference's path ended at the depth limit (Frame::depth_limited: render.max_depth reached on an
// element, drawn black) have no seen point, so they have no angular error: they are left out of it and compared
// by colour only (depthLimitColour), counted apart.
//
// Known-hard regions are reported separately, never left out: the zooming region of a pvrr patch
// (zoomingRegion) and, with rgb dispersion, the colour fringes (fringeStats).
//
// Colour error: each channel clamped to [0, 1] and sRGB-encoded (IEC 61966-2-1, as the 8-bit pictures are),
// then the RMSE over the three channels of the counted pixels and its PSNR = 20 log10(1 / RMSE) dB (peak 1).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/base/frame.h"
#include "pvrr/scene/scene.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr {

// The q-quantile (q in [0, 1]) of `values` with linear interpolation between order statistics: the value at
// position q (n - 1) of the sorted values (Hyndman and Fan's type 7; R's and NumPy's default). The median
// (q = 0.5) is therefore the middle value of an odd count and the mean of the two middle values of an even
// count. 0 for no values. NaN values are not allowed (filter them first).
double quantile(std::vector<double> values, double q);
inline double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

// The angle (radians) at `surface_point` between the directions to `seen_a` and to `seen_b`.
inline double seenAngle(const Vec3& surface_point, const Vec3& seen_a, const Vec3& seen_b) {
  return angleBetween(seen_a - surface_point, seen_b - surface_point);
}

struct ErrorStats {
  size_t pixels = 0;  // pixels counted (finite errors)
  double median_arcmin = 0, p95_arcmin = 0, max_arcmin = 0;  // 0 when no pixels
  double psnr_db = 0, rmse = 0;  // compareToReference only (0 when no pixels); 99 dB for no colour error
};

// The per-pixel angular error (arcmin) of `seen` against `ref_seen`, both measured at ref.element_point, over
// the pixels where ref.element >= 0 (and equals `only_element` when that is >= 0) and the reference's path did
// not end at the depth limit (ref.depth_limited, when filled). NaN at the other pixels and where the angle is
// not finite; all NaN when a buffer's size is not ref.element's. `ref_seen` is ref.seen,
// or one channel's ref.channel_seen.
std::vector<double> angularErrors(const Frame& ref, const std::vector<Vec3>& ref_seen, const std::vector<Vec3>& seen,
                                  int only_element = -1);

// Median, p95 and max of the finite errors, among the pixels where `region` (when given) equals `value`.
ErrorStats summarizeErrors(const std::vector<double>& errors_arcmin, const std::vector<int8_t>* region = nullptr,
                           int8_t value = 1);

// The angular error of `frame` against the reference `ref` (angularErrors of ref.seen and frame.seen,
// summarised), and the colour RMSE and PSNR of frame.color against ref.color over the same pixels.
// `errors_arcmin` (optional) receives the per-pixel errors.
ErrorStats compareToReference(const Frame& ref, const Frame& frame, std::vector<double>* errors_arcmin = nullptr,
                              int only_element = -1);

// Whether the reference's path at pixel i ended at the depth limit (false where ref.depth_limited is empty).
inline bool depthLimited(const Frame& ref, size_t i) {
  return ref.depth_limited.size() == ref.element.size() && i < ref.depth_limited.size() && ref.depth_limited[i] != 0;
}

// A colour is drawn dark when every channel's sRGB value (clamped to [0, 1]) is below kDarkSrgb, lit when one is
// above kLitSrgb. The gap between them keeps dim but seen colours (a dark wall, a tinted lens's edge) out of both
// counts: 0.05 is 13 of 255, darker than any lit surface of the shipped scenes' rooms; 0.15 is 38 of 255.
inline constexpr double kDarkSrgb = 0.05, kLitSrgb = 0.15;
bool drawnDark(const Vec3& linear);
bool drawnLit(const Vec3& linear);

// The colour check of the pixels the angular error leaves out, and its converse. Over the element pixels (ref.element
// >= 0, equal to `only_element` when that is >= 0):
struct DepthLimitColour {
  size_t pixels = 0;         // where the reference's path ended at the depth limit (the reference draws them black)
  size_t drawn_lit = 0;      // of those, the frame draws lit: it shows something where the reference shows nothing
  double psnr_db = 0;        // the frame's colour PSNR over `pixels` (0 for none, 99 when all match)
  size_t reference_lit = 0;  // the other element pixels that the reference draws lit
  size_t drawn_dark = 0;  // of those, the frame draws dark: its path ended (or was cut) where the reference's did not
  size_t disagreements() const { return drawn_lit + drawn_dark; }
};
DepthLimitColour depthLimitColour(const Frame& ref, const Frame& frame, int only_element = -1);

// The error heat maps' colour of x in [0, 1] (clamped): a perceptually ordered black-body-like ramp, black -> red
// -> yellow -> white, linear in each third. What `pvrr compare` writes (MODE-error.png) and `pvrr view` overlays.
inline Vec3 errorHeatColour(double x) {
  x = x < 0 ? 0 : x > 1 ? 1 : x;
  auto ramp = [](double v) { return v < 0 ? 0.0 : v > 1 ? 1.0 : v; };
  return Vec3(ramp(3 * x), ramp(3 * x - 1), ramp(3 * x - 2));
}
// The heat map's full-scale error (arcmin): 1.5 x the p95, at least 1 arcmin.
inline double heatMapScaleArcmin(const ErrorStats& s) { return s.p95_arcmin * 1.5 > 1.0 ? s.p95_arcmin * 1.5 : 1.0; }

// The squared sRGB difference of two linear colours (each channel clamped to [0, 1], then encoded), summed over
// R, G and B.
double srgbSquaredError(const Vec3& a, const Vec3& b);
// The RMSE of a sum of srgbSquaredError over `pixels` pixels (three samples each); 0 for no pixels.
double colourRmse(double squared_error_sum, size_t pixels);
// 20 log10(1 / rmse) dB; 99 dB for rmse 0 (no error).
double psnrDb(double rmse);
// The colour PSNR of `colour` against `truth` over the pixels where `ref` sees an element; 0 for none.
double elementPsnr(const Frame& ref, const std::vector<Vec3>& truth, const std::vector<Vec3>& colour);

// The zooming region (issue 5; docs/accuracy.md): a pixel is in it when the reference's seen point lies
// behind the fitted viewpoint of the patch under the pixel, along that patch's forward direction:
// (seen - fit.eye) . forward <= 0, where forward is the forward volume's (pvrr/method/view_volume.h: the normalised
// mean of the patch's outgoing ray directions; recomputed from the rays when the patch's volume is the
// reversed one). The patch under a pixel is the patch of the element vertex nearest the reference's element
// point. Per pixel: 1 zooming, 0 not, -1 no element pixel or an element missing from `frames`, 2 not
// classified: the reference path (ref.bounces, when given) has more specular events than the element's own
// (mirror 1, lens 2), so its seen point lies beyond a second element (a mirror seen in a mirror) or a TIR.
std::vector<int8_t> zoomingRegion(const Frame& ref, const std::vector<ElementFrame>& frames,
                                  const Scene* scene = nullptr);

// Colour fringes (issue 6): the deviation of a channel at a pixel is the angle between the eye ray (eye to
// the element point) and the line from the element point to that channel's seen point. Blue bends more than
// red where deviation(B) > deviation(R). Over the pixels in `mask` (non-zero) whose |deviation(B) -
// deviation(R)| is at least min_difference_arcmin (pixels with no dispersion are left out).
struct FringeStats {
  size_t pixels = 0;                       // pixels counted
  double median_blue_minus_red_arcmin = 0;  // median of deviation(B) - deviation(R)
  double fraction_blue_bends_more = 0;      // fraction of the counted pixels with deviation(B) > deviation(R)
};
FringeStats fringeStats(const Vec3& eye, const std::vector<Vec3>& element_point, const std::vector<Vec3>& red_seen,
                        const std::vector<Vec3>& blue_seen, const std::vector<int8_t>& mask,
                        double min_difference_arcmin = 0.01);

}  // namespace pvrr

// Golden-image tests: a picture compared against a small reference PNG kept in the tree (tests/golden/images),
// in the style of docs "image tests": a per-pixel delta, a mean delta and a failing-pixel fraction, each a named
// threshold; on failure the actual, reference and diff images are written into the build folder
// (build/golden-diff/) and their paths printed. PVRR_UPDATE_GOLDEN=1 in the environment rewrites the references
// from the actual pictures instead of comparing (review the PNGs' diff before committing them).
//
// Pictures are 8-bit sRGB (pvrr/base/image.h), rows top-down; differences are in code values (0..255).
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/base/frame.h"
#include "pvrr/base/image.h"

namespace pvrr::test {

struct GoldenTolerance {
  // A pixel fails when any of its channels differs from the reference by more than this (code values).
  double pixel_delta = 0;
  // The mean absolute difference over the channel samples of the pixels that do not fail may be at most this
  // (code values): a broad drift under pixel_delta. The failing pixels (edges that flip between surfaces on
  // another GPU) are bounded by failing_fraction instead, so that a few of them do not use up this budget.
  double mean_delta = 0;
  // At most this fraction of the pixels may fail.
  double failing_fraction = 0;
};

// The thresholds of the shipped-scene goldens, drawn on llvmpipe; they must hold on another GL implementation
// and fail on a real change. Measured (December 2026, 32 pictures at 160 x 120): the same pictures drawn by
// Mesa's softpipe (GALLIUM_DRIVER=softpipe, another rasteriser and texture filter) differ from llvmpipe's by
// at most 1 code in smooth regions, mean at most 0.13 (over all pixels), with at most 7 pixels (silhouettes,
// depth edges) over 8 codes. Changes that fail: a mirror's reflectance 0.9 -> 0.85 (mean 0.46), a point light 3% brighter
// (mean 1.45), a lens material changed (5% failing), the eye moved 1 cm (up to 10% failing).
// - pixel_delta 8: smooth shading on another GPU differs by a few codes (float ordering, FMA contraction,
//   transcendental precision, texture filtering weights); a pixel that flips between two surfaces differs by
//   far more and is counted by failing_fraction.
// - failing_fraction 0.5%: 96 of 19,200 pixels, 14 times softpipe's worst; an element covers thousands.
// - mean_delta 0.3 (over the pixels that do not fail): over twice softpipe's; catches a broad drift of a few
//   codes that stays under pixel_delta everywhere (the reflectance and light changes above).
constexpr GoldenTolerance kGoldenTolerance{8, 0.3, 0.005};

// Compares `actual` with the reference tests/golden/images/NAME.png (NAME: letters, digits, '-', '_').
// Success: the reference exists, has the same size and the differences are within `tolerance`. Failure: the
// message gives the differences and the paths of NAME-actual.png, NAME-reference.png and NAME-diff.png
// written into build/golden-diff/. With PVRR_UPDATE_GOLDEN=1 the reference is rewritten and the result is a
// success that says so.
::testing::AssertionResult matchesGolden(const std::string& name, const ImageRGB8& actual,
                                         const GoldenTolerance& tolerance = kGoldenTolerance);

// The mean absolute difference (code values) over the channel samples of the pixels whose largest channel
// difference is at most pixel_delta; 0 when there are none. Same-size images.
double meanWithinTolerance(const ImageRGB8& a, const ImageRGB8& b, double pixel_delta);

// Whether PVRR_UPDATE_GOLDEN asks for the references to be rewritten (set and not "0").
bool updatingGoldens();

}  // namespace pvrr::test

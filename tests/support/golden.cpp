#include "support/golden.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "pvrr/base/error.h"

namespace fs = std::filesystem;

namespace pvrr::test {
namespace {

// Set by tests/CMakeLists.txt: where the references live (in the source tree) and where failures write.
const char* const kGoldenDir = PVRR_GOLDEN_DIR;
const char* const kGoldenDiffDir = PVRR_GOLDEN_DIFF_DIR;

// A number as describe() prints them (the stream's default 6 significant digits), not gtest's 17.
std::string number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

bool validName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
  });
}

}  // namespace

double meanWithinTolerance(const ImageRGB8& a, const ImageRGB8& b, double pixel_delta) {
  PVRR_CHECK(a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
                 a.rgb.size() == 3 * size_t(a.width) * size_t(a.height),
             << a.width << "x" << a.height << " vs " << b.width << "x" << b.height);
  double sum = 0;
  size_t pixels = 0;
  for (size_t p = 0; p < a.rgb.size() / 3; ++p) {
    int largest = 0, total = 0;
    for (size_t c = 0; c < 3; ++c) {
      const int diff = std::abs(int(a.rgb[3 * p + c]) - int(b.rgb[3 * p + c]));
      largest = std::max(largest, diff);
      total += diff;
    }
    if (largest > pixel_delta) continue;
    sum += total;
    ++pixels;
  }
  return pixels ? sum / (3.0 * double(pixels)) : 0.0;
}

bool updatingGoldens() {
  const char* v = std::getenv("PVRR_UPDATE_GOLDEN");
  return v && *v && std::string(v) != "0";
}

::testing::AssertionResult matchesGolden(const std::string& name, const ImageRGB8& actual,
                                         const GoldenTolerance& tolerance) {
  if (!validName(name)) return ::testing::AssertionFailure() << "golden name \"" << name << "\": letters, digits, - and _ only";
  const std::string reference_path = std::string(kGoldenDir) + "/" + name + ".png";
  if (updatingGoldens()) {
    fs::create_directories(kGoldenDir);
    writePngAtomic(reference_path, actual);
    return ::testing::AssertionSuccess() << "PVRR_UPDATE_GOLDEN: wrote " << reference_path;
  }
  const fs::path diff_dir(kGoldenDiffDir);
  const std::string actual_path = (diff_dir / (name + "-actual.png")).string();
  if (!fs::exists(reference_path)) {
    fs::create_directories(diff_dir);
    writePngAtomic(actual_path, actual);
    return ::testing::AssertionFailure() << "no reference " << reference_path << " (the actual picture is "
                                         << actual_path << "; PVRR_UPDATE_GOLDEN=1 writes the references)";
  }
  const ImageRGB8 reference = readPng(reference_path);
  const bool same_size = reference.width == actual.width && reference.height == actual.height;
  ImageDiff d;
  double mean_within = 0;
  if (same_size) {
    d = compareImages(reference, actual, tolerance.pixel_delta);
    mean_within = meanWithinTolerance(reference, actual, tolerance.pixel_delta);
    if (mean_within <= tolerance.mean_delta && d.failing_fraction <= tolerance.failing_fraction)
      return ::testing::AssertionSuccess() << name << ": " << describe(d) << "; mean " << number(mean_within)
                                           << " over the other pixels";
  }
  fs::create_directories(diff_dir);
  const std::string reference_copy = (diff_dir / (name + "-reference.png")).string(),
                    diff_path = (diff_dir / (name + "-diff.png")).string();
  writePngAtomic(actual_path, actual);
  writePngAtomic(reference_copy, reference);
  ::testing::AssertionResult r = ::testing::AssertionFailure();
  r << name << " differs from " << reference_path << ": ";
  if (!same_size) {
    r << "size " << actual.width << "x" << actual.height << ", the reference's " << reference.width << "x"
      << reference.height;
  } else {
    writeDiffImage(reference, actual, diff_path);
    r << describe(d) << "; mean " << number(mean_within) << " over the other pixels (thresholds: a pixel fails over "
      << tolerance.pixel_delta << " codes; mean at most " << number(tolerance.mean_delta) << " over the other pixels; at most "
      << 100 * tolerance.failing_fraction << "% failing)";
  }
  r << "\n  actual:    " << actual_path << "\n  reference: " << reference_copy;
  if (same_size) r << "\n  diff:      " << diff_path;
  return r;
}

}  // namespace pvrr::test

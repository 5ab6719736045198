#include "pvrr/base/frame.h"

#include <algorithm>

#include "pvrr/base/error.h"

namespace pvrr {

ImageRGB8 srgbPicture(int width, int height, const std::vector<Vec3>& linear, size_t* non_finite) {
  PVRR_CHECK(width >= 0 && height >= 0 && linear.size() == size_t(width) * size_t(height),
             << width << "x" << height << " holds " << linear.size() << " colours");
  ImageRGB8 img(width, height);
  size_t bad = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Vec3 c = linear[size_t(y) * size_t(width) + size_t(x)];
      if (!isFinite(c)) {
        ++bad;
        c = Vec3(0);
      }
      uint8_t* p = img.at(x, y);
      for (int k = 0; k < 3; ++k) p[k] = linearToSrgb8(std::clamp(c[k], 0.0, 1.0));
    }
  if (non_finite) *non_finite = bad;
  return img;
}

}  // namespace pvrr

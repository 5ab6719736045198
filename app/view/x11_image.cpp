#include "app/view/x11_image.h"

#include <dlfcn.h>

#include <cstdint>

#include "pvrr/base/error.h"

// Xlib's headers last: their macros (None, Bool, Status) are for this file only.
#include <X11/Xlib.h>
#include <X11/Xutil.h>

namespace pvrr::app::view {

ImageRGB8 readX11Window(void* display, unsigned long window, int width, int height) {
  void* x11 = dlopen("libX11.so.6", RTLD_LAZY | RTLD_NOLOAD);
  const auto get_image = x11 ? reinterpret_cast<decltype(&XGetImage)>(dlsym(x11, "XGetImage")) : nullptr;
  if (!get_image) throw Error("pvrr view: cannot read the window's shown pixels: libX11 is not loaded");
  XImage* img = get_image(static_cast<Display*>(display), Window(window), 0, 0, unsigned(width), unsigned(height),
                          AllPlanes, ZPixmap);
  dlclose(x11);
  if (!img) throw Error("pvrr view: cannot read the window's shown pixels: XGetImage failed");
  const auto shift = [](unsigned long mask) {
    int s = 0;
    while (mask && !(mask & 1)) {
      mask >>= 1;
      ++s;
    }
    return s;
  };
  const bool ok = img->bits_per_pixel == 32 && img->red_mask == 0xff0000 && img->green_mask == 0xff00 &&
                  img->blue_mask == 0xff;
  ImageRGB8 out(width, height);
  if (ok) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const unsigned long p = XGetPixel(img, x, y);
        std::uint8_t* o = out.at(x, y);
        o[0] = std::uint8_t((p & img->red_mask) >> shift(img->red_mask));
        o[1] = std::uint8_t((p & img->green_mask) >> shift(img->green_mask));
        o[2] = std::uint8_t((p & img->blue_mask) >> shift(img->blue_mask));
      }
  }
  XDestroyImage(img);
  if (!ok) throw Error("pvrr view: cannot read the window's shown pixels: not a 24-bit TrueColor window");
  return out;
}

}  // namespace pvrr::app::view

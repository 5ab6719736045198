// The pixels an X11 window shows, read from the X server (XGetImage): what a frame shown in part
// (app/view/panel_cache.h) leaves on screen, for the screenshot "panel": "shown". libX11 is GLFW's; it is found in
// the process (dlopen with RTLD_NOLOAD), not linked. The only place that includes Xlib's header.
#pragma once
#include <string>

#include "pvrr/base/image.h"

namespace pvrr::app::view {

// The top-left width x height pixels of X window `window` of display `display` (a Display*), rows top-down, of a
// 24- or 32-bit TrueColor visual. Throws pvrr::Error saying why it cannot.
ImageRGB8 readX11Window(void* display, unsigned long window, int width, int height);

}  // namespace pvrr::app::view

// `pvrr view`: the interactive design-review window (issue 25). The window (window.h) shows the Renderer's frame
// of the scene's observer, turned and moved by the head (head.h), with a panel of what each stage did; a script
// (script.h) can drive it for tests and demos.
#pragma once
#include <string>
#include <vector>

namespace pvrr::app {

int cmdView(const std::vector<std::string>& args);

}  // namespace pvrr::app

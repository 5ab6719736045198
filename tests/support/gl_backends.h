// The GL tests' backends: each parameterised GL test runs on OSMesa and on EGL. Header-only.
#pragma once
#include <gtest/gtest.h>

#include <memory>

#include "pvrr/gl/context.h"

namespace pvrr::test {

// A context on backend `b`; on failure a test failure is recorded (a GL test must not pass by skipping)
// and null returned, so the test returns at once: `auto ctx = glContextOrFail(GetParam()); if (!ctx) return;`.
inline std::unique_ptr<gl::GlContext> glContextOrFail(gl::GlBackend b) {
  try {
    return gl::GlContext::create(b);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "no GL context: " << e.what();
    return nullptr;
  }
}

// Instantiates the parameterised GL test suite `suite` on both backends, named OsMesa and Egl.
#define PVRR_GL_BACKENDS(suite)                                                                          \
  INSTANTIATE_TEST_SUITE_P(Backends, suite, ::testing::Values(gl::GlBackend::OsMesa, gl::GlBackend::Egl), \
                           [](const auto& info) { return info.param == gl::GlBackend::OsMesa ? "OsMesa" : "Egl"; })

}  // namespace pvrr::test

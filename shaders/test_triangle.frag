#version 330 core
// Test-only (tests/gl/platform/context_test.cpp): a flat colour into attachment 0 and, into attachment 1, the window
// coordinates of the fragment (gl_FragCoord.xy, pixel centres at +0.5, origin at the BOTTOM-left) plus a constant.
uniform vec4 u_color;
uniform float u_value;

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_coords;

void main() {
#ifdef PVRR_TEST_SWAP_RED_BLUE
  o_color = u_color.bgra;
#else
  o_color = u_color;
#endif
  o_coords = vec4(gl_FragCoord.xy, u_value, 1.0);
}

#version 330 core
// The part of a first-pass map that no element reads (pvrr/method/map_footprint.h): quads in the map's NDC, drawn
// into the depth buffer only, at the depth that no later fragment of the pass passes (0 for GL_LESS, 1 for
// the reversed GL_GREATER), so the environment is not shaded there.
layout(location = 0) in vec2 a_ndc;
uniform float u_ndc_z;
void main() { gl_Position = vec4(a_ndc, u_ndc_z, 1.0); }

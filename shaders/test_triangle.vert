#version 330 core
// Test-only (tests/gl/platform/context_test.cpp): passes 2D positions given in normalised device coordinates through.
layout(location = 0) in vec2 a_position_ndc;

void main() { gl_Position = vec4(a_position_ndc, 0.0, 1.0); }

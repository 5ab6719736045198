#version 330 core
// The viewer's present pass (app/view/present_pass.h): each fragment of the window copies its texel of the
// renderer's frame (Renderer::colorTexture, linear, the window's size), sRGB-encoded as pvrr render encodes it.
#include "srgb_encode.glsl"
uniform sampler2D u_frame;
out vec4 out_color;
void main() {
  out_color = vec4(srgbEncode(texelFetch(u_frame, ivec2(gl_FragCoord.xy), 0).rgb), 1.0);
}

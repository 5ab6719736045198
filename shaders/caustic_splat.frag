#version 330 core
// The tent kernel one cell wide (the reference's deposit, pvrr/trace/light_tracer.h): bilinear weights to the
// four nearest cell centres, summing to 1; irradiance = power x weight / cell area, summed by additive blending.
flat in vec2 v_pixel;
flat in vec3 v_power;
uniform float u_inv_cell_area;
layout(location = 0) out vec4 o_irradiance;
void main() {
  vec2 w = max(vec2(0.0), 1.0 - abs(gl_FragCoord.xy - v_pixel));
  o_irradiance = vec4(v_power * (w.x * w.y * u_inv_cell_area), 0.0);
}

#version 330 core
// The caustic map's texels: the photon's exit ray (w = 1 marks a photon) and its power per unit measure.
in vec3 v_origin;
in vec3 v_direction;
in vec3 v_power;
layout(location = 0) out vec4 o_origin;
layout(location = 1) out vec4 o_direction;
layout(location = 2) out vec4 o_power;
void main() {
  o_origin = vec4(v_origin, 1.0);
  o_direction = vec4(v_direction, 0.0);
  o_power = vec4(v_power, 0.0);
}

#version 330 core
// The caustic map's texels: the photon's exit ray (origin w = 1 marks a photon; direction w: the mesh it meets
// first, the same at a triangle's three corners) and its power per unit measure (w: the distance along the ray to
// that mesh, interpolated between the exact hits at the corners; a curved receiver's landing point).
in vec3 v_origin;
in vec3 v_direction;
in vec3 v_power;
flat in float v_mesh;
in float v_t;
layout(location = 0) out vec4 o_origin;
layout(location = 1) out vec4 o_direction;
layout(location = 2) out vec4 o_power;
void main() {
  o_origin = vec4(v_origin, 1.0);
  o_direction = vec4(v_direction, v_mesh);
  o_power = vec4(v_power, v_t);
}

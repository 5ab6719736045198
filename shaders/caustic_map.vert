#version 330 core
// A photon mesh (pvrr/method/caustic_mesh.h) rasterized over its aperture: one photon per texel, its exit
// ray and power per unit aperture measure interpolated between the exact photons at the mesh's vertices.
layout(location = 0) in vec2 a_ndc;       // the vertex's aperture coordinates, as normalised device coordinates
layout(location = 1) in vec3 a_origin;    // where it leaves the element, relative to the mesh's anchor
layout(location = 2) in vec3 a_direction;
layout(location = 3) in vec3 a_power;     // W per unit aperture measure
layout(location = 4) in float a_mesh;     // the receiving surface its exit ray meets first (-1: none; CausticVertex::surface)
layout(location = 5) in float a_t;        // the distance along the exit ray to that mesh (exact; 0: none)
out vec3 v_origin;
out vec3 v_direction;
out vec3 v_power;
flat out float v_mesh;
out float v_t;
void main() {
  v_origin = a_origin;
  v_direction = a_direction;
  v_power = a_power;
  v_mesh = a_mesh;
  v_t = a_t;
  gl_Position = vec4(a_ndc, 0.0, 1.0);
}

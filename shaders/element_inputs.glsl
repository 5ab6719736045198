// The inputs of every element fragment shader (element_plain.frag, element_pvrr.frag, element_envmap.frag,
// element_impostor.frag): element.vert's outputs and the uniforms all modes share.
#include "cpp_constants.glsl"
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_st0;
in vec3 v_st1;
in vec3 v_st2;
in vec3 v_w0;
in vec3 v_w1;
in vec3 v_w2;
in vec3 v_st_seen;
in vec4 v_tir;        // PVRR lens: the tracer's colour of totally reflected channels (their map weight is 0)
in vec3 v_tir_seen;
uniform vec3 u_view_origin;      // where the viewing rays start, relative to the camera origin
uniform float u_element_id;      // index + 1
uniform bool u_metal;
uniform vec3 u_reflectance;
uniform vec3 u_metal_n;
uniform vec3 u_metal_k;
uniform vec3 u_seen_offset;      // (the map's camera origin) - (this pass's camera origin)
uniform bool u_additive;         // the second or later of the additive draws of more than three channels

#version 330 core
// Opaque casters write depth only; a lens (LENS) writes its transmittance per channel beside its depth:
// (1 - R0)^2 (u_fresnel), times a tinted lens's absorption along the chord through its glass, interpolated
// between the caster's vertices (pvrr/gl/shadow_pass.h; the reference's shadow rays: pvrr/trace/shadow_rays.h).
#if defined(LENS)
uniform vec3 u_fresnel;
uniform vec3 u_absorption_per_m;
uniform bool u_tinted;  // false: a clear lens (or a light whose caustics are on), u_fresnel as it is
in float v_chord;
layout(location = 0) out vec4 o_transmittance;
void main() {
  vec3 t = u_fresnel;
  if (u_tinted) t *= exp(-u_absorption_per_m * v_chord);
  o_transmittance = vec4(t, 1.0);
}
#else
void main() {}
#endif

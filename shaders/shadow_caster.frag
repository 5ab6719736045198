#version 330 core
// Opaque casters write depth only; a lens (LENS) writes its transmittance per channel beside its depth:
// (1 - R0)^2, times its glass's absorption over its mean thickness for a tinted lens (lensShadowPassed,
// pvrr/trace/shadow_rays.h).
#if defined(LENS)
uniform vec3 u_transmittance;
layout(location = 0) out vec4 o_transmittance;
void main() { o_transmittance = vec4(u_transmittance, 1.0); }
#else
void main() {}
#endif

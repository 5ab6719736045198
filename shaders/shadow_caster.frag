#version 330 core
// Opaque casters write depth only; a lens (LENS) writes its transmittance (1 - R0)^2 beside its depth
// (pvrr/trace/shadow_rays.h).
#if defined(LENS)
uniform float u_transmittance;
layout(location = 0) out vec4 o_transmittance;
void main() { o_transmittance = vec4(u_transmittance); }
#else
void main() {}
#endif

// GL_LINEAR with clamp-to-edge, computed with float weights from four texelFetch: a GPU's filter weights have
// about 8 fractional bits, which would quantise the surfaces' heights and normals between samples to 1/256 of
// their difference (~4e-6 rad of normal on the concave mirror's map). No mipmaps, so fetching inside the
// searches' loops, whose exits differ between neighbouring fragments, is well defined.
vec4 bilinear(sampler2D t, vec2 st) {
  ivec2 size = textureSize(t, 0);
  vec2 x = st * vec2(size) - 0.5, f = floor(x), a = x - f;
  ivec2 i0 = clamp(ivec2(f), ivec2(0), size - 1), i1 = clamp(ivec2(f) + 1, ivec2(0), size - 1);
  return mix(mix(texelFetch(t, i0, 0), texelFetch(t, ivec2(i1.x, i0.y), 0), a.x),
             mix(texelFetch(t, ivec2(i0.x, i1.y), 0), texelFetch(t, i1, 0), a.x), a.y);
}

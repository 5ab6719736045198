// The viewer's sRGB encode of a linear colour (app/view/present_pass.h): exactly pvrr::linearToSrgb8 (the CPU's
// double encode that pvrr render writes) of the 16-bit value k = round(c * 65535) that the renderer's RGBA16
// target holds (a float target is rounded to them first: at most 1/131070 off, under 0.03 of a code), from a
// table of 4096 buckets of 16 consecutive k (the uniform block SrgbBuckets, filled by srgbBucketWords): bucket
// j = k >> 4 holds the code of its first value (bits 0-7) and the offset in the bucket where the code steps up
// by one (bits 8-12; 16: no step). No bucket holds two steps: the codes' thresholds lie at least 19.9 values of
// k apart (the linear segment's 65535 / (12.92 * 255)). One read of a 16-byte block a channel; llvmpipe reads
// this faster than the 65536-texel texture it replaces (docs/performance.md).
layout(std140) uniform SrgbBuckets {
  uvec4 srgb_buckets[512];  // 8 buckets of 16 bits each, the lower half of each 32-bit word first
};

// The 8-bit code of linear c (clamped to [0, 1]), as a unorm value (code / 255).
float srgbCode(float c) {
  int k = int(clamp(c, 0.0, 1.0) * 65535.0 + 0.5);
  int j = k >> 4;
  uint word = srgb_buckets[j >> 3][(j >> 1) & 3];
  uint bucket = (word >> uint(16 * (j & 1))) & 0xFFFFu;
  uint code = (bucket & 255u) + ((uint(k & 15) >= (bucket >> 8)) ? 1u : 0u);
  return float(code) * (1.0 / 255.0);
}

vec3 srgbEncode(vec3 c) { return vec3(srgbCode(c.r), srgbCode(c.g), srgbCode(c.b)); }

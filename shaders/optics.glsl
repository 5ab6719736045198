// Fresnel reflectance, as the reference tracer computes it (pvrr/optics/optics.cpp): cos_i of the incident angle,
// indices real (dielectric) or complex n + i k (conductor).
// Exact unpolarised dielectric Fresnel reflectance from index n1 into n2 (pvrr/optics/optics.cpp fresnelDielectric).
float fresnelDielectric(float cos_i, float n1, float n2) {
  float eta = n1 / n2, s2t = eta * eta * (1.0 - cos_i * cos_i);
  if (s2t >= 1.0) return 1.0;
  float cos_t = sqrt(1.0 - s2t);
  float rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  float rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// Exact unpolarised conductor Fresnel reflectance, outside index 1 (pvrr/optics/optics.cpp fresnelConductor).
float fresnelConductor(float cos_i, float n, float k) {
  float c2 = cos_i * cos_i, s2 = 1.0 - c2;
  float a = n * n - k * k - s2;
  float b = sqrt(a * a + 4.0 * n * n * k * k);
  float a2b2 = b;
  float A = sqrt(max(0.0, 0.5 * (a2b2 + a)));
  float rs = (a2b2 + c2 - 2.0 * A * cos_i) / (a2b2 + c2 + 2.0 * A * cos_i);
  float rp = rs * (c2 * a2b2 + s2 * s2 - 2.0 * A * cos_i * s2) / (c2 * a2b2 + s2 * s2 + 2.0 * A * cos_i * s2);
  return 0.5 * (rs + rp);
}

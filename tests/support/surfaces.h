// Small surfaces built in code for the tessellation tests. Header-only.
#pragma once
#include <string>

#include "cad/surface.h"

namespace pvrr::test {

// The unit square z = 0 whose normal() points against du x dv (violating the convention): the grid's triangles
// must still wind counter-clockwise about the normals.
class FlippedPlane : public cad::Surface {
 public:
  cad::ParamDomain domain() const override { return {}; }
  cad::SurfaceDerivs evaluate(double u, double v) const override {
    cad::SurfaceDerivs d{};
    d.p = Vec3(u, v, 0);
    d.du = Vec3(1, 0, 0);
    d.dv = Vec3(0, 1, 0);
    return d;
  }
  Vec3 normal(double, double) const override { return Vec3(0, 0, -1); }
  std::string describe() const override { return "flipped plane"; }
};

}  // namespace pvrr::test

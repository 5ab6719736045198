// OpenCASCADE helpers shared by the STEP/IGES reader (cad_import.cpp) and writer (cad_export.cpp). Private
// to cad/: no header outside cad/ includes it, so OCCT types stay out of the public headers.
#pragma once
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <gp_Pnt.hxx>

#include <mutex>
#include <string>

#include "pvrr/base/math.h"

namespace pvrr::cad::occt {

// OCCT keeps its translation settings in process-wide statics; one translation at a time.
std::mutex& translationMutex();

// OCCT prints coloured statistics to stdout through its default messenger; our stdout stays clean. Also
// initialises the IGES controller. Idempotent.
void silence();

// "Type: message" of an OCCT exception.
std::string failureMessage(const Standard_Failure& f);

struct LengthUnit {
  std::string name;
  double mm = 1;  // one unit in millimetres
};

inline Vec3 toVec(const gp_Pnt& p) { return Vec3(p.X(), p.Y(), p.Z()); }

// The diagonal of the poles' bounding box (the model size that relative tolerances scale with).
double poleSize(const Handle(Geom_BSplineSurface)& bs);

}  // namespace pvrr::cad::occt

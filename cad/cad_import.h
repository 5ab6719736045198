// STEP and IGES import and export through OpenCASCADE, and Catmull-Clark subdivision cages through
// OpenSubdiv. No OCCT or OpenSubdiv type appears in this header.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cad/nurbs.h"
#include "cad/outline.h"

namespace pvrr::cad {

struct ImportedFace {
  std::shared_ptr<const NurbsSurface> surface;  // in the file's own length unit
  std::optional<Outline> trim;                  // outer trim loop in (u, v), when the face is trimmed
  std::string source_type;                      // "b-spline", "plane", "sphere", "cylinder", "torus", ...
  // Honesty about the sampled trim loop (0 when untrimmed): the largest distance between the exact trim curve,
  // taken at the mid-parameter of each chord, and that chord; in (u, v) units and, on the surface, in the
  // file's length unit.
  double trim_chord_error_uv = 0;
  double trim_chord_error = 0;
};

struct ImportedModel {
  std::vector<ImportedFace> faces;
  std::string unit_name;        // e.g. "mm"
  double unit_to_metres = 1e-3; // multiply file lengths by this to get metres
};

// Reads a .step/.stp or .igs/.iges file (chosen by extension, case-insensitive). Analytic faces are
// converted exactly to rational B-splines. Throws pvrr::Error naming the file for a missing, empty,
// broken or truncated file, or one with no surface.
ImportedModel importCadFile(const std::string& path);

// Scales every control point (units conversion).
NurbsSurface scaled(const NurbsSurface& s, double factor);

// Writes one face (optionally trimmed by a loop in (u, v)) in the given unit ("mm" or "m"). Atomic: writes a
// temporary file and renames it.
void writeStep(const std::string& path, const NurbsSurface& s, const std::optional<Outline>& trim,
               const std::string& unit = "mm");
void writeIges(const std::string& path, const NurbsSurface& s, const std::optional<Outline>& trim,
               const std::string& unit = "mm");

// A Catmull-Clark limit surface of an OBJ quad cage whose faces form a regular grid (after OpenSubdiv's
// topology analysis). Parameters: (u, v) in [0, faces_u] x [0, faces_v]; face (a, b) covers
// [a, a+1] x [b, b+1]. Positions and normals are evaluated exactly at the limit (Bfr). Throws pvrr::Error
// for a cage that is not a quad grid, with the file and what was found.
std::shared_ptr<const Surface> loadSubdivisionCage(const std::string& obj_path);

}  // namespace pvrr::cad

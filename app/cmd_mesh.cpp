// pvrr mesh: tessellate a surface (a CAD file or a subdivision cage in its own units, or a scene's element
// in world metres) and export it with normals from the exact surface.
#include <cstdio>
#include <filesystem>

#include "app/args.h"
#include "app/report.h"
#include "cad/cad_import.h"
#include "pvrr/base/error.h"

namespace fs = std::filesystem;

namespace pvrr::app {

namespace {

cad::Tessellation tessellate(const cad::Surface& s, const cad::Outline* outline, int n, double tol) {
  if (tol > 0) return cad::tessellateAdaptive(s, tol, radians(5.0), outline);
  return cad::tessellateGrid(s, n, n, outline);
}

}  // namespace

int cmdMesh(const std::vector<std::string>& argv) {
  Args a("mesh", argv, {"element", "tessellation", "tolerance", "out", "set"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("mesh", "expected one SURFACE_FILE or SCENE");
  auto out = a.get("out");
  if (!out) usageError("mesh", "--out FILE.obj|.ply|.vtp is required");
  if (a.has("tessellation") && a.has("tolerance")) usageError("mesh", "give --tessellation or --tolerance, not both");
  const int n = a.getInt("tessellation", 33, 2);
  const double tol = a.getDouble("tolerance", 0.0);
  if (a.has("tolerance") && !(tol > 0)) usageError("mesh", "--tolerance: expected a length > 0");
  const std::string input = a.positional()[0];
  std::string ext = fs::path(input).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));

  cad::Tessellation t;
  if (ext == ".json") {
    if (!a.has("element")) usageError("mesh", "a scene needs --element NAME");
    LoadedScene ls = loadScene(input, a.all("set"));
    const Element* el = nullptr;
    std::vector<std::string> names;
    for (const Element& e : ls.scene.elements) {
      names.push_back(e.name);
      if (e.name == *a.get("element")) el = &e;
    }
    if (!el) {
      const std::string hint = nearest(*a.get("element"), names);
      throw Error(input + ": no element named \"" + *a.get("element") + "\"" + (hint.empty() ? "" : "; did you mean \"" + hint + "\"?"));
    }
    t = tessellate(el->frontSurface(), el->has_outline ? &el->outline : nullptr, n, tol);
    for (Vec3& p : t.positions) p = el->toWorldPoint(p);
    for (Vec3& v : t.normals) v = glm::normalize(el->toWorldDir(v));
  } else {
    if (a.has("element")) usageError("mesh", "--element applies to a scene file only");
    if (ext == ".step" || ext == ".stp" || ext == ".igs" || ext == ".iges") {
      cad::ImportedModel m = cad::importCadFile(input);
      if (m.faces.empty()) throw Error(input + ": no surface in the file");
      const cad::ImportedFace& f = m.faces[0];
      t = tessellate(*f.surface, f.trim ? &*f.trim : nullptr, n, tol);
      if (m.faces.size() > 1)
        std::fprintf(stderr, "pvrr mesh: %s has %zu faces; wrote the first\n", input.c_str(), m.faces.size());
    } else if (ext == ".obj") {
      t = tessellate(*cad::loadSubdivisionCage(input), nullptr, n, tol);
    } else {
      usageError("mesh", "expected a .step, .stp, .igs, .iges or .obj (subdivision cage) file, or a scene .json");
    }
  }
  writeTessellation(*out, t);
  std::printf("%s\n%zu vertices, %zu triangles\n", out->c_str(), t.positions.size(), t.triangles.size());
  return 0;
}

}  // namespace pvrr::app

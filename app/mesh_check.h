// Checks of environment mesh files (OBJ, PLY) before VTK reads them. VTK's readers accept face indices
// beyond the vertex list, read "nan" in an OBJ as 0, and crash on some malformed PLY files (a vertex
// element without y and z, binary data shorter than the header declares); these checks read the whole
// file the way the format defines it and throw pvrr::Error naming the file and the place
// ("env.obj:12: face 3: vertex index 9 is out of range (the file has 8 vertices)"). No VTK here, so the
// fuzz targets (tests/fuzz) can run them alone.
#pragma once
#include <string>

namespace pvrr::app {

// `text` is the whole OBJ file, `path` names it in messages. Checks that every v/vt/vn number is finite
// and every face index (v, v/vt, v//vn, v/vt/vn; negative = relative) refers to an existing entry, and that
// the file has at least one face.
void checkObjText(const std::string& text, const std::string& path);

// `data` is the whole PLY file (ascii or binary, either byte order). Checks the header (a vertex element
// with x, y and z, a face element with a vertex_indices list), that the data holds every element the header
// declares, that the vertex properties are finite and that every face index is in range.
void checkPlyData(const std::string& data, const std::string& path);

}  // namespace pvrr::app

// Checks of STL environment meshes before VTK's vtkSTLReader reads them. VTK's reader reads a binary file
// cut short without a word (the triangles that are there), and takes nan as a coordinate. These checks read
// the file the way the format defines it and throw a pvrr::Error naming the file and the place
// ("cone.stl: triangle 7: vertex 2 is not finite"). No VTK here, so the fuzz target
// (tests/fuzz/stl_fuzz.cpp) can run them alone.
#pragma once
#include <cstddef>
#include <string>

namespace pvrr::app {

// `data` is the whole file, `path` names it in messages. Binary (an 80-byte header, a triangle count n, then
// exactly 50 n bytes) or ASCII ("solid", then facets "facet normal nx ny nz / outer loop / vertex x y z (x3)
// / endloop / endfacet", then "endsolid"). Checks the size or the syntax, finite vertices and at least one
// triangle; returns the number of triangles.
size_t checkStlData(const std::string& data, const std::string& path);

}  // namespace pvrr::app

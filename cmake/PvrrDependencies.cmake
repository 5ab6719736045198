# Every third-party dependency, found once here. Traps: ../shared/notes/platform.md.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(glm REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(PNG REQUIRED)
find_package(TBB REQUIRED)
find_package(embree 3 REQUIRED)
find_package(Ceres REQUIRED)

# OpenSubdiv's CMake config is broken on Debian 12 (it names static libraries that are not shipped).
find_path(OSD_INCLUDE_DIR opensubdiv/version.h REQUIRED)
find_library(OSD_CPU_LIBRARY NAMES osdCPU REQUIRED)
add_library(OpenSubdiv::osdCPU UNKNOWN IMPORTED)
set_target_properties(OpenSubdiv::osdCPU PROPERTIES IMPORTED_LOCATION "${OSD_CPU_LIBRARY}"
                      INTERFACE_INCLUDE_DIRECTORIES "${OSD_INCLUDE_DIR}")

# OCCT: no version (ExactVersion policy), no COMPONENTS subset; the targets carry no include dirs.
find_package(OpenCASCADE REQUIRED)
add_library(pvrr_occt INTERFACE)
target_include_directories(pvrr_occt SYSTEM INTERFACE ${OpenCASCADE_INCLUDE_DIR})
target_link_libraries(pvrr_occt INTERFACE TKernel TKMath TKG2d TKG3d TKGeomBase TKGeomAlgo TKBRep TKTopAlgo
                      TKPrim TKMesh TKShHealing TKXSBase TKSTEP TKIGES)

# GL: OSMesa through pkg-config; EGL through GLVND. Entry points come from glad only (both libOSMesa and
# libOpenGL export gl*; never call them directly).
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS EGL)

# glad2, generated offline at configure time (--reproducible: use the XML bundled with python3-glad).
find_program(GLAD_EXE glad REQUIRED)
set(GLAD_OUT ${CMAKE_BINARY_DIR}/glad)
if(NOT EXISTS ${GLAD_OUT}/src/gl.c)
  execute_process(COMMAND ${GLAD_EXE} --api gl:core=4.5 --extensions GL_KHR_debug --out-path ${GLAD_OUT}
                          --reproducible --quiet c
                  RESULT_VARIABLE glad_rc OUTPUT_QUIET)
  if(NOT glad_rc EQUAL 0)
    message(FATAL_ERROR "glad generation failed (${glad_rc}); is python3-glad installed?")
  endif()
endif()
add_library(pvrr_glad STATIC ${GLAD_OUT}/src/gl.c)
target_include_directories(pvrr_glad SYSTEM PUBLIC ${GLAD_OUT}/include)

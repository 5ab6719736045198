# Warnings for the project's own targets (never global add_definitions).
function(pvrr_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  if(PVRR_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# pvrr_embed_shaders(TARGET <t> DIR <dir>): embeds every *.vert/*.frag/*.geom/*.glsl file of DIR into the
# target as a generated C++ table, looked up by file name at run time (pvrr::gl::shaderSource()).
function(pvrr_embed_shaders)
  cmake_parse_arguments(A "" "TARGET;DIR" "" ${ARGN})
  file(GLOB shader_files CONFIGURE_DEPENDS ${A_DIR}/*.vert ${A_DIR}/*.frag ${A_DIR}/*.geom ${A_DIR}/*.glsl)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} "-DFILES=${shader_files}" -P ${CMAKE_SOURCE_DIR}/cmake/EmbedShaders.cmake
    DEPENDS ${shader_files} ${CMAKE_SOURCE_DIR}/cmake/EmbedShaders.cmake
    COMMENT "Embedding shaders"
    VERBATIM)
  target_sources(${A_TARGET} PRIVATE ${out})
endfunction()

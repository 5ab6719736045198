// GLSL programs built from the shader files embedded at build time (shaders/*.vert|frag|geom|glsl, looked up by
// file name, see cmake/EmbedShaders.cmake). Variants are made by #define lines inserted after the #version line.
// Everything here needs a current pvrr::gl::GlContext.
#pragma once
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace pvrr::gl {

class GlContext;

// The file names of all embedded shaders, sorted.
std::vector<std::string> embeddedShaderNames();

// The source of the embedded shader `file_name` ("test_triangle.vert"). Throws pvrr::Error listing the available
// names when there is none. Needs no GL context.
std::string shaderSource(const std::string& file_name);

// A shader's file name (used in every message) and its text.
struct ShaderSource {
  std::string name;
  std::string text;
};

// `source` with `defines` inserted after its #version line (at the top when it has none), followed by a #line
// directive so that compiler messages keep the file's own line numbers. Each define is a full line
// ("#define PVRR_REFRACT 1"); a line not starting with '#' gets "#define " prepended ("PVRR_REFRACT 1").
std::string insertDefines(const std::string& source, const std::vector<std::string>& defines);

class Program {
 public:
  // Compiles and links the embedded files `vertex_file` and `fragment_file`. A compile or link failure throws
  // pvrr::Error with the file name(s), the defines and the driver's info log.
  Program(const std::string& vertex_file, const std::string& fragment_file,
          const std::vector<std::string>& defines = {});
  // The same from given texts (tests, and shaders generated at run time); names are used only in messages.
  static Program fromSources(const ShaderSource& vertex, const ShaderSource& fragment,
                             const std::vector<std::string>& defines = {});

  // Deletes the program if its context is current (otherwise the name dies with its context).
  ~Program();
  Program(Program&& other) noexcept;
  Program& operator=(Program&& other) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  unsigned int id() const { return id_; }
  // "a.vert + b.frag", for messages.
  const std::string& label() const { return label_; }
  void use() const;

  // The location of an active uniform (cached), or -1 when the program has no active uniform of that name (unused
  // uniforms are removed by the compiler, so -1 is not an error). Array elements: "name[2]".
  int uniformLocation(const std::string& name) const;
  bool hasUniform(const std::string& name) const { return uniformLocation(name) >= 0; }

  // Setters make this program current (glUseProgram) and ignore uniforms that are not active. Matrices are
  // column-major (GL and glm convention).
  void set(const std::string& name, float value) const;
  void set(const std::string& name, int value) const;
  void set(const std::string& name, const glm::vec2& value) const;
  void set(const std::string& name, const glm::vec3& value) const;
  void set(const std::string& name, const glm::vec4& value) const;
  void set(const std::string& name, const glm::mat3& value) const;
  void set(const std::string& name, const glm::mat4& value) const;
  void setVec2(const std::string& name, const float* xy, int count = 1) const;
  void setVec3(const std::string& name, const float* xyz, int count = 1) const;
  void setVec4(const std::string& name, const float* xyzw, int count = 1) const;
  void setMat4(const std::string& name, const float* column_major, int count = 1) const;
  void setFloats(const std::string& name, const float* values, int count) const;

 private:
  Program(unsigned int id, std::string label, GlContext* context)
      : id_(id), label_(std::move(label)), context_(context) {}
  void release() noexcept;
  void requireContext() const;  // throws unless context_ is current

  unsigned int id_ = 0;
  std::string label_;
  GlContext* context_ = nullptr;  // the context that owns id_
  mutable std::unordered_map<std::string, int> locations_;
};

}  // namespace pvrr::gl

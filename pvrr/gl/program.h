// GLSL programs built from the shader files embedded at build time (shaders/*.vert|frag|geom|glsl, looked up by
// file name, see cmake/EmbedShaders.cmake). Variants are made by #define lines inserted after the #version line.
// Everything here needs a current pvrr::gl::GlContext.
#pragma once
#include <functional>
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

// A shader's file name (used in every message) and its text. `files`: the files spliced into `text` by
// shaderWithIncludes, by number (files[0] is `name`; empty: the text has no other); compiler messages are
// translated through it ("0:100012(3): error" -> "optics.glsl:12(3): error" for files[1]).
struct ShaderSource {
  std::string name;
  std::string text;
  std::vector<std::string> files = {};
};

// Line numbers of shader file S (shaderWithIncludes) start at S kShaderFileLines + 1: no file has more lines.
inline constexpr int kShaderFileLines = 100000;

// The text of a shader file by name (shaderSource for the embedded files; tests give their own).
using ShaderFileLookup = std::function<std::string(const std::string& file_name)>;

// The shader `file_name` with every line `#include "other.glsl"` replaced by that file's text, recursively; a
// file already included into this shader is not included again (once-only: libraries need no include guards).
// Each file gets a number S in order of first inclusion (0: `file_name`) and its text is framed by
// "#line (S kShaderFileLines + 1) S" before and "#line (P kShaderFileLines + N) P" after (P, N: the including
// file's number and next line), so that compiler messages name the true file and line (ShaderSource::files).
// The file is in the line number as well as in GLSL's source-string number because Mesa reports source string
// 0 for every location its parser derives from a rule rather than a token (YYLLOC_DEFAULT), with the right line
// and column: the line number is what the log translation reads. GLSL has no #include, and the splicing
// happens before the preprocessor: an #include inside #if/#ifdef/#ifndef throws pvrr::Error (it would be
// spliced, and counted once-only, whatever the condition), as does an unknown file (naming the including
// file and line). `lookup` defaults to the embedded files.
ShaderSource shaderWithIncludes(const std::string& file_name, const ShaderFileLookup& lookup = shaderSource);

// GLSL source texts for values that C++ owns (one constant, not retyped in shaders), as the virtual include
// file kCppConstantsFile: shaders `#include "cpp_constants.glsl"` and shaderWithIncludes supplies it. Floats
// are written so that GLSL parses the same float as the C++ constant rounded to float.
inline constexpr const char* kCppConstantsFile = "cpp_constants.glsl";
std::string cppConstantsSource();
// `value` rounded to float, as a GLSL float literal that parses to exactly that float: the shortest decimal that
// round-trips ("0.05", "1e-05", "2.0"); infinities and NaN throw pvrr::Error (GLSL has no literal for them).
std::string glslFloat(double value);

// `source` with `defines` inserted after its #version line (at the top when it has none), followed by a #line
// directive so that compiler messages keep the file's own line numbers. Each define is a full line
// ("#define PVRR_REFRACT 1"); a line not starting with '#' gets "#define " prepended ("PVRR_REFRACT 1").
std::string insertDefines(const std::string& source, const std::vector<std::string>& defines);

// How many programs this thread has compiled and linked (Program::fromSources, which every Program goes through):
// a window that must never compile while it draws (`pvrr view`'s live reference) checks that this stays put.
int programsBuiltOnThisThread();

class Program {
 public:
  // Compiles and links the embedded files `vertex_file` and `fragment_file`, their #includes resolved
  // (shaderWithIncludes). A compile or link failure throws pvrr::Error with the file name(s), the defines and the
  // driver's info log, its locations translated to file names.
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

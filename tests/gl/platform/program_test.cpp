// Shader includes (pvrr/gl/program.h shaderWithIncludes): nested, once-only, with #line directives that let a
// compile error name the included file and its own line; and the shipped shaders' entry files resolve.
#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pvrr/base/error.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/program.h"

namespace pvrr::gl {
namespace {

// In-memory shader files for the include tests.
ShaderFileLookup filesOf(std::map<std::string, std::string> files) {
  return [files = std::move(files)](const std::string& name) {
    auto it = files.find(name);
    if (it == files.end()) throw Error("no test shader \"" + name + "\"");
    return it->second;
  };
}

TEST(ShaderIncludes, NestedFilesAreSplicedOnceWithLineDirectives) {
  const auto lookup = filesOf({{"main.frag",
                                "#version 330 core\n#include \"a.glsl\"\n#include \"b.glsl\"\nvoid main() {}\n"},
                               {"a.glsl", "#include \"b.glsl\"\nfloat a() { return b(); }\n"},
                               {"b.glsl", "float b() { return 1.0; }\n"}});
  const ShaderSource s = shaderWithIncludes("main.frag", lookup);
  EXPECT_EQ(s.name, "main.frag");
  EXPECT_EQ(s.files, (std::vector<std::string>{"main.frag", "a.glsl", "b.glsl"}));
  EXPECT_EQ(s.text,
            "#version 330 core\n"
            "#line 100001 1\n"
            "#line 200001 2\n"
            "float b() { return 1.0; }\n"
            "#line 100002 1\n"
            "float a() { return b(); }\n"
            "#line 3 0\n"
            "// #include \"b.glsl\": included already\n"
            "void main() {}\n");
}

TEST(ShaderIncludes, IncludeInsideAConditionalOrOfAnUnknownFileNamesTheLine) {
  const auto lookup = filesOf({{"cond.frag", "#version 330 core\n#if defined(X)\n#include \"a.glsl\"\n#endif\n"},
                               {"missing.frag", "#version 330 core\n\n#include \"nowhere.glsl\"\n"}});
  try {
    shaderWithIncludes("cond.frag", lookup);
    FAIL() << "an #include inside #if was spliced";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cond.frag:3: #include inside #if"), std::string::npos) << e.what();
  }
  try {
    shaderWithIncludes("missing.frag", lookup);
    FAIL() << "an unknown include was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.frag:3: no test shader \"nowhere.glsl\""), std::string::npos)
        << e.what();
  }
}

TEST(ShaderIncludes, CppConstantsAreAVirtualInclude) {
  const auto lookup = filesOf({{"c.frag", "#version 330 core\n#include \"cpp_constants.glsl\"\n"}});
  const ShaderSource s = shaderWithIncludes("c.frag", lookup);
  EXPECT_EQ(s.files, (std::vector<std::string>{"c.frag", kCppConstantsFile}));
  EXPECT_NE(s.text.find(cppConstantsSource()), std::string::npos) << s.text;
}

TEST(ShaderIncludes, CppFloatsAreWrittenAsTheSameGlslFloat) {
  EXPECT_EQ(glslFloat(0.05), "0.05");
  EXPECT_EQ(glslFloat(2.0), "2.0");
  EXPECT_EQ(glslFloat(-0.25), "-0.25");
  for (double v : {0.05, 1.0 / 3.0, 1e-5, 6.02e23, -7.5e-12})
    EXPECT_EQ(std::strtof(glslFloat(v).c_str(), nullptr), static_cast<float>(v)) << glslFloat(v);
  EXPECT_THROW(glslFloat(1e300), Error);
  EXPECT_NE(cppConstantsSource().find("#define MIRROR_BACK_ALBEDO 0.05 "), std::string::npos) << cppConstantsSource();
}

TEST(ShaderIncludes, EveryEmbeddedShaderResolves) {
  for (const std::string& name : embeddedShaderNames()) {
    const std::string text = shaderWithIncludes(name).text;
    EXPECT_EQ(text.find("\n#include"), std::string::npos) << name;
    EXPECT_NE(text.rfind("#include", 0), 0u) << name;
  }
}

std::unique_ptr<GlContext> contextOrSkip(std::string* skip_reason) {
  try {
    return GlContext::create(glBackendFromEnvironment(GlBackend::Auto));
  } catch (const Error& e) {
    const char* require = std::getenv("PVRR_TEST_REQUIRE_GL");
    if (require != nullptr && std::string(require) == "1") ADD_FAILURE() << "PVRR_TEST_REQUIRE_GL=1 but: " << e.what();
    *skip_reason = std::string("no GL context can be created here: ") + e.what();
    return nullptr;
  }
}

// A compile error in a file included two deep, after prepended defines, is reported at that file's own line,
// and so is one in the entry file after the includes.
TEST(ShaderIncludes, CompileErrorNamesTheIncludedFileAndItsLine) {
  std::string skip;
  const auto context = contextOrSkip(&skip);
  if (!context) GTEST_SKIP() << skip;
  const ShaderSource vert{"test_triangle.vert", shaderSource("test_triangle.vert")};
  const auto lookup = filesOf({{"entry.frag",
                                "#version 330 core\n"
                                "out vec4 o;\n"
                                "#include \"outer.glsl\"\n"
                                "void main() {\n"
                                "  o = vec4(inner() + outer());\n"
                                "#if defined(BREAK_ENTRY)\n"
                                "  o = entry_undeclared;\n"
                                "#endif\n"
                                "}\n"},
                               {"outer.glsl", "// outer\n#include \"inner.glsl\"\nfloat outer() { return 1.0; }\n"},
                               {"inner.glsl",
                                "// inner: three lines of comment\n"
                                "//\n"
                                "//\n"
                                "float inner() {\n"
                                "#if defined(BREAK_INNER)\n"
                                "  return inner_undeclared;\n"
                                "#endif\n"
                                "  return 0.5;\n"
                                "}\n"}});
  const ShaderSource frag = shaderWithIncludes("entry.frag", lookup);
  EXPECT_NO_THROW(Program::fromSources(vert, frag, {"#define UNUSED_1", "#define UNUSED_2"}));
  const auto errorOf = [&](const char* define) {
    try {
      Program::fromSources(vert, frag, {"#define UNUSED_1", define});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(compiled)");
  };
  const std::string inner = errorOf("#define BREAK_INNER");
  std::cout << "[ message  ] " << inner << "\n";
  EXPECT_NE(inner.find("inner.glsl:6("), std::string::npos) << inner;
  EXPECT_NE(inner.find("inner_undeclared"), std::string::npos) << inner;
  EXPECT_EQ(inner.find("entry.frag:6("), std::string::npos) << inner;  // Mesa's source string 0, not its file
  EXPECT_EQ(inner.find("100006"), std::string::npos) << inner;
  const std::string entry = errorOf("#define BREAK_ENTRY");
  EXPECT_NE(entry.find("entry.frag:7("), std::string::npos) << entry;
  EXPECT_NE(entry.find("entry_undeclared"), std::string::npos) << entry;
}

}  // namespace
}  // namespace pvrr::gl

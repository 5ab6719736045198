#include "app/stl_check.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

constexpr size_t kHeaderBytes = 80, kTriangleBytes = 50;

// ASCII when it starts with "solid" and its first bytes are text (a binary file's header may start with
// "solid" too, but its triangle data is not text).
bool looksAscii(const std::string& d) {
  size_t i = 0;
  while (i < d.size() && std::isspace(static_cast<unsigned char>(d[i]))) ++i;
  if (d.compare(i, 5, "solid") != 0) return false;
  const size_t n = std::min<size_t>(d.size(), 512);
  for (size_t k = 0; k < n; ++k) {
    const unsigned char c = static_cast<unsigned char>(d[k]);
    if ((c < 32 && c != '\n' && c != '\r' && c != '\t') || c > 126) return false;
  }
  return true;
}

size_t checkBinary(const std::string& d, const std::string& path) {
  if (d.size() < kHeaderBytes + 4)
    throw Error(path + ": not an STL file (" + std::to_string(d.size()) +
                " bytes: neither ASCII text starting with \"solid\" nor a binary STL's 84-byte header)");
  uint32_t n = 0;
  std::memcpy(&n, d.data() + kHeaderBytes, 4);  // little endian, as x86
  const uint64_t expected = kHeaderBytes + 4 + uint64_t(n) * kTriangleBytes;
  if (d.size() != expected)
    throw Error(path + ": the binary STL header declares " + std::to_string(n) + " triangles (" +
                std::to_string(expected) + " bytes), the file has " + std::to_string(d.size()) + " bytes");
  if (n == 0) throw Error(path + ": the file holds no triangles");
  for (uint32_t t = 0; t < n; ++t)
    for (int v = 0; v < 3; ++v) {
      float p[3];
      std::memcpy(p, d.data() + kHeaderBytes + 4 + size_t(t) * kTriangleBytes + 12 + 12 * size_t(v), 12);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw Error(path + ": triangle " + std::to_string(t) + ": vertex " + std::to_string(v) + " is not finite");
    }
  return n;
}

// Whitespace-separated tokens with the line each starts on.
struct Token {
  std::string text;
  size_t line;
};

std::vector<Token> tokens(const std::string& d) {
  std::vector<Token> out;
  size_t line = 1, i = 0;
  while (i < d.size()) {
    if (d[i] == '\n') ++line;
    if (std::isspace(static_cast<unsigned char>(d[i]))) {
      ++i;
      continue;
    }
    const size_t b = i;
    while (i < d.size() && !std::isspace(static_cast<unsigned char>(d[i]))) ++i;
    out.push_back(Token{d.substr(b, i - b), line});
  }
  return out;
}

std::string shown(const std::string& s) { return "\"" + s.substr(0, 24) + (s.size() > 24 ? "...\"" : "\""); }

class AsciiReader {
 public:
  AsciiReader(const std::string& d, const std::string& path) : tok_(tokens(d)), path_(path) {}

  size_t run() {
    expect("solid");
    // The solid's name: everything up to the first "facet" or "endsolid".
    while (i_ < tok_.size() && tok_[i_].text != "facet" && tok_[i_].text != "endsolid") ++i_;
    size_t facets = 0;
    while (i_ < tok_.size() && tok_[i_].text == "facet") {
      ++i_;
      expect("normal");
      for (int k = 0; k < 3; ++k) number(facets, -1);  // the normal (VTK does not use it)
      expect("outer");
      expect("loop");
      for (int v = 0; v < 3; ++v) {
        expect("vertex");
        for (int k = 0; k < 3; ++k) number(facets, v);
      }
      expect("endloop");
      expect("endfacet");
      ++facets;
    }
    expect("endsolid");
    if (facets == 0) throw Error(path_ + ": the file holds no triangles");
    return facets;
  }

 private:
  std::string where() const {
    const size_t line = i_ < tok_.size() ? tok_[i_].line : (tok_.empty() ? 1 : tok_.back().line);
    return path_ + ":" + std::to_string(line) + ": ";
  }
  void expect(const char* word) {
    if (i_ >= tok_.size()) throw Error(where() + "expected \"" + word + "\", the file ends");
    if (tok_[i_].text != word) throw Error(where() + "expected \"" + word + "\", got " + shown(tok_[i_].text));
    ++i_;
  }
  void number(size_t facet, int vertex) {
    if (i_ >= tok_.size()) throw Error(where() + "expected a number, the file ends");
    const std::string& t = tok_[i_].text;
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size()) throw Error(where() + "expected a number, got " + shown(t));
    if (vertex >= 0 && !std::isfinite(v))
      throw Error(where() + "triangle " + std::to_string(facet) + ": vertex " + std::to_string(vertex) +
                  " is not finite (" + shown(t) + ")");
    ++i_;
  }

  std::vector<Token> tok_;
  const std::string& path_;
  size_t i_ = 0;
};

}  // namespace

size_t checkStlData(const std::string& data, const std::string& path) {
  if (looksAscii(data)) return AsciiReader(data, path).run();
  return checkBinary(data, path);
}

}  // namespace pvrr::app

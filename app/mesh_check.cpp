#include "app/mesh_check.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

// At most this many characters of a token are quoted in a message (a binary file's "token" can be long).
constexpr size_t kQuoteMax = 24;

std::string quoted(const std::string& s) {
  std::string q;
  for (char c : s.substr(0, kQuoteMax)) q += (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) ? '?' : c;
  return "\"" + q + (s.size() > kQuoteMax ? "...\"" : "\"");
}

// "3 vertices", "1 normal", "2 faces".
std::string counted(long long n, const std::string& noun) {
  std::string s = std::to_string(n) + " " + noun;
  if (n == 1) return s;
  if (noun.size() >= 2 && noun.compare(noun.size() - 2, 2, "ex") == 0) return s.substr(0, s.size() - 2) + "ices";
  return s + "s";
}

std::vector<std::string> splitWhitespace(const std::string& line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t b = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// strtod on the whole token; false when it is not a number. `value` may be inf or nan.
bool parseDouble(const std::string& token, double& value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size()) return false;
  // strtod sets ERANGE for values beyond double's range (returning inf) and for denormals; only the first is
  // not finite and is caught by the caller.
  return true;
}

bool parseInteger(const std::string& token, long long& value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtoll(token.c_str(), &end, 10);
  return end == token.c_str() + token.size() && errno == 0;
}

// ---------------------------------------------------------------------------------------------------------
// OBJ

struct ObjLine {
  size_t number;  // 1-based line number of the line's start
  std::string text;
};

// Lines without comments, with '\r' dropped and backslash continuations joined.
std::vector<ObjLine> objLines(const std::string& text) {
  std::vector<ObjLine> lines;
  size_t number = 1, pos = 0;
  std::string pending;
  size_t pending_start = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(pos, nl - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (pending.empty()) pending_start = number;
    if (!line.empty() && line.back() == '\\') {
      line.pop_back();
      pending += line + " ";
    } else {
      pending += line;
      const size_t hash = pending.find('#');
      if (hash != std::string::npos) pending.erase(hash);
      lines.push_back(ObjLine{pending_start, pending});
      pending.clear();
    }
    ++number;
    pos = nl + 1;
  }
  if (!pending.empty()) lines.push_back(ObjLine{pending_start, pending});
  return lines;
}

}  // namespace

void checkObjText(const std::string& text, const std::string& path) {
  const std::vector<ObjLine> lines = objLines(text);
  // Pass 1: the numbers of the v, vt, vn lines and their counts (a face may refer to a vertex given later).
  long long count[3] = {0, 0, 0};  // v, vt, vn
  const char* kind_name[3] = {"vertex", "texture coordinate", "normal"};
  size_t faces = 0;
  for (const ObjLine& l : lines) {
    const std::vector<std::string> tok = splitWhitespace(l.text);
    if (tok.empty()) continue;
    const std::string where = path + ":" + std::to_string(l.number) + ": ";
    int kind = -1;
    size_t need = 0;
    if (tok[0] == "v") kind = 0, need = 3;
    else if (tok[0] == "vt") kind = 1, need = 1;
    else if (tok[0] == "vn") kind = 2, need = 3;
    if (kind >= 0) {
      if (tok.size() < need + 1)
        throw Error(where + tok[0] + " expects " + std::to_string(need) + " numbers, got " + std::to_string(tok.size() - 1));
      // Only the numbers VTK reads are checked: x y z of v and vn, u v of vt (v may carry colours after them).
      const size_t used = kind == 1 ? std::min<size_t>(tok.size() - 1, 2) : 3;
      for (size_t k = 1; k <= used; ++k) {
        double x = 0;
        if (!parseDouble(tok[k], x)) throw Error(where + tok[0] + ": expected a number, got " + quoted(tok[k]));
        if (!std::isfinite(x))
          throw Error(where + kind_name[kind] + " " + std::to_string(count[kind]) + ": expected a finite number, got " +
                      quoted(tok[k]));
      }
      ++count[kind];
    }
  }
  // Pass 2: every face index against the counts (negative indices against the count so far).
  long long so_far[3] = {0, 0, 0};
  for (const ObjLine& l : lines) {
    const std::vector<std::string> tok = splitWhitespace(l.text);
    if (tok.empty()) continue;
    if (tok[0] == "v") ++so_far[0];
    else if (tok[0] == "vt") ++so_far[1];
    else if (tok[0] == "vn") ++so_far[2];
    if (tok[0] != "f") continue;
    const std::string where = path + ":" + std::to_string(l.number) + ": face " + std::to_string(faces) + ": ";
    if (tok.size() < 4) throw Error(where + "expected at least 3 vertices, got " + std::to_string(tok.size() - 1));
    for (size_t k = 1; k < tok.size(); ++k) {
      // v, v/vt, v//vn or v/vt/vn
      std::string part[3];
      size_t n_parts = 0;
      size_t b = 0;
      while (n_parts < 3) {
        const size_t slash = tok[k].find('/', b);
        part[n_parts++] = tok[k].substr(b, slash == std::string::npos ? std::string::npos : slash - b);
        if (slash == std::string::npos) break;
        b = slash + 1;
      }
      if (n_parts == 3 && tok[k].find('/', b) != std::string::npos)
        throw Error(where + "expected v, v/vt, v//vn or v/vt/vn, got " + quoted(tok[k]));
      for (size_t p = 0; p < n_parts; ++p) {
        if (p > 0 && part[p].empty()) continue;  // v//vn, v/vt/
        long long idx = 0;
        if (!parseInteger(part[p], idx) || idx == 0)
          throw Error(where + "expected a " + kind_name[p] + " index (1-based, or negative), got " + quoted(tok[k]));
        const long long resolved = idx > 0 ? idx : so_far[p] + idx + 1;
        if (resolved < 1 || resolved > count[p])
          throw Error(where + kind_name[p] + " index " + part[p] + " is out of range (the file has " +
                      counted(count[p], kind_name[p]) + ")");
      }
    }
    ++faces;
  }
  if (count[0] == 0) throw Error(path + ": the file holds no vertices (no \"v\" lines)");
  if (faces == 0) throw Error(path + ": the file holds no faces (no \"f\" lines)");
}

// ---------------------------------------------------------------------------------------------------------
// PLY

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool plyType(const std::string& s, PlyType& t) {
  static const struct {
    const char* name;
    PlyType type;
  } table[] = {{"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
               {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
               {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
               {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
               {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
               {"float64", PlyType::Float64}};
  for (const auto& e : table)
    if (s == e.name) {
      t = e.type;
      return true;
    }
  return false;
}

size_t plySize(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}

// A value read from a PLY file, for messages: integers without a fraction.
std::string number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (v == std::floor(v) && std::fabs(v) < 1e18) return std::to_string(static_cast<long long>(v));
  return std::to_string(v);
}

bool isFloat(PlyType t) { return t == PlyType::Float32 || t == PlyType::Float64; }

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::UInt8, type = PlyType::Float32;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

// Reads the body one value at a time, ascii or binary.
class PlyBody {
 public:
  PlyBody(const std::string& data, size_t pos, int format) : data_(data), pos_(pos), format_(format) {}

  // False at the end of the data (or, in ascii, on a token that is not a number: `bad` holds it).
  bool read(PlyType t, double& value, std::string& bad) {
    if (format_ == 0) {
      while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
      const size_t b = pos_;
      while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
      if (pos_ == b) return false;
      const std::string token = data_.substr(b, pos_ - b);
      if (isFloat(t)) {
        if (!parseDouble(token, value)) {
          bad = token;
          return false;
        }
      } else {
        long long v = 0;
        if (!parseInteger(token, v)) {
          bad = token;
          return false;
        }
        value = double(v);
      }
      return true;
    }
    const size_t n = plySize(t);
    if (data_.size() - pos_ < n) return false;
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if (format_ == 2) std::reverse(b, b + n);  // big endian -> little (x86)
    switch (t) {
      case PlyType::Int8: value = double(static_cast<int8_t>(b[0])); break;
      case PlyType::UInt8: value = double(b[0]); break;
      case PlyType::Int16: { int16_t v; std::memcpy(&v, b, 2); value = v; break; }
      case PlyType::UInt16: { uint16_t v; std::memcpy(&v, b, 2); value = v; break; }
      case PlyType::Int32: { int32_t v; std::memcpy(&v, b, 4); value = v; break; }
      case PlyType::UInt32: { uint32_t v; std::memcpy(&v, b, 4); value = v; break; }
      case PlyType::Float32: { float v; std::memcpy(&v, b, 4); value = double(v); break; }
      case PlyType::Float64: { double v; std::memcpy(&v, b, 8); value = v; break; }
    }
    return true;
  }

 private:
  const std::string& data_;
  size_t pos_;
  int format_;  // 0 ascii, 1 binary little endian, 2 binary big endian
};

}  // namespace

void checkPlyData(const std::string& data, const std::string& path) {
  const std::string not_ply = path + ": not a PLY file (it does not start with the line \"ply\")";
  // The header: lines up to "end_header".
  size_t pos = 0;
  std::vector<std::string> header;
  for (;;) {
    const size_t nl = data.find('\n', pos);
    if (nl == std::string::npos) {
      if (header.empty()) throw Error(not_ply);
      throw Error(path + ": the PLY header has no end_header line");
    }
    std::string line = data.substr(pos, nl - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = nl + 1;
    if (header.empty() && line != "ply") throw Error(not_ply);
    header.push_back(line);
    if (line == "end_header") break;
  }
  int format = -1;
  std::vector<PlyElement> elements;
  for (size_t i = 1; i + 1 < header.size(); ++i) {
    const std::vector<std::string> tok = splitWhitespace(header[i]);
    const std::string where = path + ":" + std::to_string(i + 1) + ": ";
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() != 3 || tok[2] != "1.0") throw Error(where + "expected \"format <kind> 1.0\", got " + quoted(header[i]));
      if (tok[1] == "ascii") format = 0;
      else if (tok[1] == "binary_little_endian") format = 1;
      else if (tok[1] == "binary_big_endian") format = 2;
      else throw Error(where + "expected ascii, binary_little_endian or binary_big_endian, got " + quoted(tok[1]));
    } else if (tok[0] == "element") {
      long long n = 0;
      // A bound far above any mesh pvrr can use, so that counts times sizes cannot overflow.
      if (tok.size() != 3 || !parseInteger(tok[2], n) || n < 0 || n > (1LL << 31))
        throw Error(where + "expected \"element <name> <count>\", got " + quoted(header[i]));
      elements.push_back(PlyElement{tok[1], n, {}});
    } else if (tok[0] == "property") {
      if (elements.empty()) throw Error(where + "a property before any element");
      PlyProperty p;
      bool ok = false;
      if (tok.size() == 5 && tok[1] == "list") {
        p.list = true;
        ok = plyType(tok[2], p.count_type) && plyType(tok[3], p.type) && !isFloat(p.count_type);
        p.name = tok[4];
      } else if (tok.size() == 3) {
        ok = plyType(tok[1], p.type);
        p.name = tok[2];
      }
      if (!ok) throw Error(where + "expected \"property <type> <name>\" or \"property list <type> <type> <name>\", got " + quoted(header[i]));
      elements.back().properties.push_back(p);
    } else {
      throw Error(where + "unknown header line " + quoted(header[i]));
    }
  }
  if (format < 0) throw Error(path + ": the PLY header has no format line");
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" && !face) face = &e;
  }
  if (!vertex) throw Error(path + ": the PLY header declares no vertex element");
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const PlyProperty& p : vertex->properties) found = found || (p.name == axis && !p.list);
    if (!found) throw Error(path + ": the PLY vertex element has no property " + axis);
  }
  if (!face || face->count == 0) throw Error(path + ": the PLY file holds no faces");
  bool has_indices = false;
  for (const PlyProperty& p : face->properties) has_indices = has_indices || (p.list && p.name == "vertex_indices");
  if (!has_indices) throw Error(path + ": the PLY face element has no list property vertex_indices");

  PlyBody body(data, pos, format);
  for (const PlyElement& e : elements) {
    for (long long i = 0; i < e.count; ++i) {
      const std::string where = path + ": " + e.name + " " + std::to_string(i) + ": ";
      for (const PlyProperty& p : e.properties) {
        double v = 0;
        std::string bad;
        const auto need = [&](PlyType t) {
          if (body.read(t, v, bad)) return;
          if (!bad.empty()) throw Error(where + p.name + ": expected a number, got " + quoted(bad));
          throw Error(where + "the data ends here (the header declares " + counted(e.count, e.name) + ")");
        };
        if (!p.list) {
          need(p.type);
          if (&e == vertex && !std::isfinite(v))
            throw Error(where + p.name + ": expected a finite number, got " + (std::isnan(v) ? "nan" : "inf"));
          continue;
        }
        need(p.count_type);
        if (!(v >= 0) || v != std::floor(v)) throw Error(where + p.name + ": expected a list length >= 0, got " + number(v));
        const long long n = static_cast<long long>(v);
        for (long long k = 0; k < n; ++k) {
          need(p.type);
          if (&e == face && p.name == "vertex_indices" && (!(v >= 0) || v >= double(vertex->count) || v != std::floor(v)))
            throw Error(where + "vertex index " + number(v) +
                        " is out of range (the file has " + counted(vertex->count, "vertex") + ")");
        }
      }
    }
  }
}

}  // namespace pvrr::app

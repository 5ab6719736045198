// The typed JSON reads behind the scene parser (pvrr/scene/scene_json.cpp and scene_json_sections.cpp): the
// context (file, unit, --set overrides) whose errors name the file and the JSON path, ranges, vectors, objects
// with known keys, choices from name tables, rotations. Private to pvrr/scene.
#pragma once
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "pvrr/base/error.h"
#include "pvrr/base/names.h"
#include "pvrr/scene/animation.h"
#include "pvrr/scene/scene_desc.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::scene_json_detail {

using json = nlohmann::json;
namespace fs = std::filesystem;

// Shorter than this (in the file's unit) a direction is "zero": no scene quantity is that small, so a
// vector this short is a typo, not a geometry.
constexpr double kZeroVectorLength = 1e-12;
// Two points closer than this (metres) are "the same point" (eye == target).
constexpr double kSamePoint_m = 1e-9;
// Directions whose angle is within this of 0 or pi (radians) are "parallel": a frame built from them would
// be dominated by rounding (up vs. view, up vs. element normal).
constexpr double kParallelAngle_rad = 1e-6;
// Largest pixel dimension accepted for images and maps (GL 4.5 guarantees at least 16384).
constexpr int kMaxImageSize = 16384;
// Largest procedural texture side (textures stay small; docs/scene-format.md).
constexpr int kMaxTextureSize = 1024;

// ---------------------------------------------------------------------------------------------------------
// Messages

inline std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

inline std::string show(const json* j) {
  if (!j) return "nothing";
  if (j->is_number_float() && !std::isfinite(j->get<double>())) return fmt(j->get<double>());
  std::string s = j->dump();
  constexpr size_t kMaxShown = 60;
  if (s.size() > kMaxShown) s = s.substr(0, kMaxShown - 3) + "...";
  return s;
}

inline std::string inQuotes(const std::string& s) { return "\"" + s + "\""; }

inline std::string joinQuoted(const std::vector<std::string>& v, const char* last_sep = " or ") {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) {
    if (i > 0) out += (i + 1 == v.size()) ? last_sep : ", ";
    out += inQuotes(v[i]);
  }
  return out;
}

// E's names in quotes, as alternatives: "\"mirror\" | \"lens\"".
template <class E>
std::string alternatives() {
  std::string out;
  for (const std::string& name : nameVector<E>()) out += (out.empty() ? "" : " | ") + inQuotes(name);
  return out;
}

inline std::string lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

inline bool startsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

inline bool endsWithAny(const std::string& s, const std::vector<std::string>& exts) {
  const std::string l = lower(s);
  for (const std::string& e : exts)
    if (l.size() >= e.size() && l.compare(l.size() - e.size(), e.size(), e) == 0) return true;
  return false;
}

// The nearest option within a typo's distance, or "" (case is ignored).
inline std::string nearest(const std::string& word, const std::vector<std::string>& options) {
  std::string best;
  int best_d = INT_MAX;
  for (const std::string& o : options) {
    const int d = editDistance(lower(word), lower(o));
    if (d < best_d) {
      best_d = d;
      best = o;
    }
  }
  // A third of the word's letters may be wrong; words of one or two letters get no suggestion ("cm" is not
  // a typo of "m").
  const int allowed = word.size() <= 2 ? 0 : std::max(1, static_cast<int>(word.size()) / 3);
  return best_d <= allowed ? best : std::string();
}

inline std::string childPath(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
inline std::string indexPath(const std::string& path, size_t i) { return path + "[" + std::to_string(i) + "]"; }

// ---------------------------------------------------------------------------------------------------------
// Context: file name, folder, unit, overrides (for " (from --set ...)" notes).

struct Override {
  std::string path;  // normalised, e.g. elements[0].tessellation
  std::string text;  // as given
};

inline bool relatedPaths(const std::string& a, const std::string& b) {
  const auto under = [](const std::string& p, const std::string& q) {
    return p == q || startsWith(p, q + ".") || startsWith(p, q + "[");
  };
  return under(a, b) || under(b, a);
}

struct Ctx {
  std::string file;
  std::string base_dir;
  std::string units = "m";
  double unit_m = 1;
  std::vector<Override> overrides;

  [[noreturn]] void fail(const std::string& path, const std::string& msg) const {
    std::string m = file + ": " + (path.empty() ? std::string("(top level)") : path) + ": " + msg;
    for (auto it = overrides.rbegin(); it != overrides.rend(); ++it) {
      if (relatedPaths(path, it->path)) {
        m += " (from --set " + it->text + ")";
        break;
      }
    }
    throw Error(m);
  }
  [[noreturn]] void expected(const std::string& path, const std::string& what, const json* got) const {
    fail(path, "expected " + what + ", got " + show(got));
  }
};

// ---------------------------------------------------------------------------------------------------------
// Typed reads of one JSON value at a path.

struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string text(const std::string& noun) const {
    const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
    if (!has_lo && !has_hi) return "a finite " + noun.substr(noun.find(' ') + 1);
    if (has_lo && !has_hi) return noun + (lo_open ? " > " : " >= ") + fmt(lo);
    if (!has_lo) return noun + (hi_open ? " < " : " <= ") + fmt(hi);
    return noun + " in " + (lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) + (hi_open ? ")" : "]");
  }
};
inline const Range kAny{};
inline const Range kPositive{0, kInf, true, false};
inline const Range kNonNegative{0, kInf, false, false};
inline Range closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Range open(double lo, double hi) { return {lo, hi, true, true}; }
inline Range leftOpen(double lo, double hi) { return {lo, hi, true, false}; }

inline double readNumber(const Ctx& c, const json* j, const std::string& path, const Range& r,
                  const std::string& noun = "a number") {
  if (!j || !j->is_number()) c.expected(path, r.text(noun), j);
  const double v = j->get<double>();
  if (!std::isfinite(v) || !r.contains(v)) c.expected(path, r.text(noun), j);
  return v;
}

inline int readInt(const Ctx& c, const json* j, const std::string& path, int lo, int hi) {
  const std::string what = hi == INT_MAX ? "an integer >= " + std::to_string(lo)
                                         : "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!j || !j->is_number()) c.expected(path, what, j);
  const double v = j->get<double>();
  if (!std::isfinite(v) || v != std::floor(v) || v < lo || v > hi) c.expected(path, what, j);
  return static_cast<int>(v);
}

enum class VecKind { Point, Direction, Colour01, ColourNonNegative, Size, Positive };

inline std::string vecText(VecKind k, int n) {
  const std::string xyz = n == 3 ? "[x, y, z]" : "[x, y]";
  switch (k) {
    case VecKind::Point: return "a point " + xyz + " of " + std::to_string(n) + " finite numbers";
    case VecKind::Direction: return "a non-zero direction " + xyz;
    case VecKind::Colour01: return "a colour [r, g, b] with each in [0, 1]";
    case VecKind::ColourNonNegative: return "a colour [r, g, b] with each >= 0";
    case VecKind::Size: return "a size " + std::string(n == 3 ? "[x, y, z]" : "[w, h]") + " with each > 0";
    case VecKind::Positive: return "an array of " + std::to_string(n) + " numbers, each > 0";
  }
  return "";
}

template <int N>
glm::vec<N, double> readVec(const Ctx& c, const json* j, const std::string& path, VecKind k) {
  const std::string what = vecText(k, N);
  if (!j || !j->is_array() || j->size() != N) c.expected(path, what, j);
  glm::vec<N, double> v(0.0);
  for (int i = 0; i < N; ++i) {
    const json& e = (*j)[i];
    if (!e.is_number() || !std::isfinite(e.get<double>())) c.expected(path, what, j);
    v[i] = e.get<double>();
    const bool ok = (k == VecKind::Colour01)            ? (v[i] >= 0 && v[i] <= 1)
                    : (k == VecKind::ColourNonNegative) ? v[i] >= 0
                    : (k == VecKind::Size || k == VecKind::Positive) ? v[i] > 0
                                                                      : true;
    if (!ok) c.expected(path, what, j);
  }
  if (k == VecKind::Direction) {
    if (glm::length(v) <= kZeroVectorLength) c.expected(path, what, j);
    v = glm::normalize(v);
  }
  return v;
}

inline void unknownKey(const Ctx& c, const std::string& path, const std::string& key, const std::vector<std::string>& keys) {
  const std::string near = nearest(key, keys);
  if (!near.empty()) c.fail(childPath(path, key), "unknown key; did you mean " + inQuotes(near) + "?");
  c.fail(childPath(path, key), "unknown key; expected one of " + joinQuoted(keys));
}

// An object at a path whose keys must all be in `keys`.
class Obj {
 public:
  Obj(const Ctx& c, const json* j, std::string path, const std::string& what, std::vector<std::string> keys)
      : c_(c), j_(j), path_(std::move(path)) {
    if (!j || !j->is_object()) c.expected(path_, what, j);
    for (auto it = j->begin(); it != j->end(); ++it)
      if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) unknownKey(c, path_, it.key(), keys);
  }
  const Ctx& ctx() const { return c_; }
  const std::string& path() const { return path_; }
  const json& value() const { return *j_; }
  const json* get(const std::string& k) const {
    auto it = j_->find(k);
    return it == j_->end() ? nullptr : &*it;
  }
  bool has(const std::string& k) const { return get(k) != nullptr; }
  std::string at(const std::string& k) const { return childPath(path_, k); }
  [[noreturn]] void expected(const std::string& k, const std::string& what) const { c_.expected(at(k), what, get(k)); }

  double number(const std::string& k, const Range& r, const std::string& noun = "a number") const {
    return readNumber(c_, get(k), at(k), r, noun);
  }
  double number(const std::string& k, const Range& r, double def, const std::string& noun = "a number") const {
    return has(k) ? number(k, r, noun) : def;
  }
  // A length in the file's unit, returned in metres.
  double length(const std::string& k, const Range& r) const { return number(k, r, "a length") * c_.unit_m; }
  double length(const std::string& k, const Range& r, double def_m) const {
    return has(k) ? length(k, r) : def_m;
  }
  int integer(const std::string& k, int lo, int hi) const { return readInt(c_, get(k), at(k), lo, hi); }
  int integer(const std::string& k, int lo, int hi, int def) const { return has(k) ? integer(k, lo, hi) : def; }
  bool boolean(const std::string& k, bool def) const {
    if (!has(k)) return def;
    if (!get(k)->is_boolean()) expected(k, "true or false");
    return get(k)->get<bool>();
  }
  std::string string(const std::string& k) const {
    const json* j = get(k);
    if (!j || !j->is_string() || j->get<std::string>().empty()) expected(k, "a non-empty string");
    return j->get<std::string>();
  }
  std::string string(const std::string& k, const std::string& def) const { return has(k) ? string(k) : def; }
  std::string choice(const std::string& k, const std::vector<std::string>& options) const {
    const json* j = get(k);
    const std::string what = "one of " + joinQuoted(options);
    if (!j || !j->is_string()) expected(k, what);
    const std::string s = j->get<std::string>();
    if (std::find(options.begin(), options.end(), s) != options.end()) return s;
    const std::string near = nearest(s, options);
    c_.fail(at(k), "expected " + what + ", got " + show(j) + (near.empty() ? "" : "; did you mean " + inQuotes(near) + "?"));
  }
  std::string choice(const std::string& k, const std::vector<std::string>& options, const std::string& def) const {
    return has(k) ? choice(k, options) : def;
  }
  // A name from E's table (pvrr/base/names.h); the message lists the choices in the table's order.
  template <class E>
  E choice(const std::string& k) const {
    return *parseName<E>(choice(k, nameVector<E>()));
  }
  template <class E>
  E choice(const std::string& k, E def) const {
    return has(k) ? choice<E>(k) : def;
  }
  Vec3 vec3(const std::string& k, VecKind kind) const { return readVec<3>(c_, get(k), at(k), kind); }
  Vec3 vec3(const std::string& k, VecKind kind, Vec3 def) const { return has(k) ? vec3(k, kind) : def; }
  Vec2 vec2(const std::string& k, VecKind kind) const { return readVec<2>(c_, get(k), at(k), kind); }
  // A point in the file's unit, returned in metres.
  Vec3 point(const std::string& k) const { return vec3(k, VecKind::Point) * c_.unit_m; }
  Vec3 point(const std::string& k, Vec3 def_m) const { return has(k) ? point(k) : def_m; }

  // A file named relative to the scene's folder, with one of the extensions, that must exist.
  std::string file(const std::string& k, const std::vector<std::string>& exts, const std::string& what) const {
    const std::string rel = string(k);
    if (!endsWithAny(rel, exts)) expected(k, what + " (" + joinQuoted(exts) + ")");
    fs::path p(rel);
    if (p.is_relative() && !c_.base_dir.empty()) p = fs::path(c_.base_dir) / p;
    p = p.lexically_normal();
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) expected(k, "an existing " + what + " (looked for " + inQuotes(p.string()) + ")");
    return p.string();
  }

 private:
  const Ctx& c_;
  const json* j_;
  std::string path_;
};

// Reads "type"-like discriminators before the key set is known: the value must be an object holding `key`.
inline std::string peekChoice(const Ctx& c, const json* j, const std::string& path, const std::string& what,
                       const std::string& key, const std::vector<std::string>& options) {
  if (!j || !j->is_object()) c.expected(path, what, j);
  std::vector<std::string> keys;
  for (auto it = j->begin(); it != j->end(); ++it) keys.push_back(it.key());
  // Only `key` is checked here; the caller's Obj checks the rest against the set for the chosen option.
  return Obj(c, j, path, what, keys).choice(key, options);
}
// The same for a name from E's table, of the values `keep` accepts (in the table's order).
template <class E, class Keep>
E peekChoice(const Ctx& c, const json* j, const std::string& path, const std::string& what, const std::string& key,
             Keep keep) {
  return *parseName<E>(peekChoice(c, j, path, what, key, nameVectorIf<E>(keep)));
}
template <class E>
E peekChoice(const Ctx& c, const json* j, const std::string& path, const std::string& what, const std::string& key) {
  return peekChoice<E>(c, j, path, what, key, [](E) { return true; });
}

inline const json* arrayAt(const Ctx& c, const json* j, const std::string& path, const std::string& what) {
  if (j && !j->is_array()) c.expected(path, what, j);
  return j;
}

// ---------------------------------------------------------------------------------------------------------
// Rotations: rotation_deg [x, y, z] is R = Rz * Ry * Rx (about the fixed parent axes, x first);
// axis_angle {axis, angle_deg} is a right-handed rotation about the axis.

inline Mat3 rotationAbout(const Vec3& axis, double angle_rad) { return Mat3(glm::rotate(Mat4(1.0), angle_rad, axis)); }

inline Mat3 readRotation(const Obj& o) {
  if (o.has("rotation_deg") && o.has("axis_angle"))
    o.ctx().fail(o.at("axis_angle"), "expected either \"rotation_deg\" or \"axis_angle\", got both");
  if (o.has("rotation_deg")) {
    return rotationFromDeg(o.vec3("rotation_deg", VecKind::Point));
  }
  if (o.has("axis_angle")) {
    Obj aa(o.ctx(), o.get("axis_angle"), o.at("axis_angle"), "an object {\"axis\": [x, y, z], \"angle_deg\": a}",
           {"axis", "angle_deg"});
    return rotationAbout(aa.vec3("axis", VecKind::Direction), radians(aa.number("angle_deg", kAny, "an angle")));
  }
  return Mat3(1.0);
}

// The scene file's sections, read into the description (scene_json_sections.cpp).
SceneDesc readScene(Ctx& c, const json& doc);
// The `vehicle` section (scene_json_vehicle.cpp); `environment` for the obstructions' names.
VehicleDesc readVehicle(const Ctx& c, const json* j, const std::vector<EnvObjectDesc>& environment);

}  // namespace pvrr::scene_json_detail

// The scene file's sections (docs/scene-format.md) read into the description: textures and materials, the
// observer, lights, environment objects, surfaces and outlines, elements and the render section (the vehicle:
// scene_json_vehicle.cpp).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "pvrr/optics/material.h"
#include "pvrr/scene/scene_json_read.h"
#include "pvrr/scene/texture_gen.h"

namespace pvrr::scene_json_detail {
namespace {

// ---------------------------------------------------------------------------------------------------------
// Textures and materials

struct ProceduralSpec {
  TextureDesc::Kind kind;  // named by kTextureKindNames
  int resolution;
  Vec3 a, b;
  std::vector<std::string> keys;  // besides procedural, resolution, seed, a, b
};

const std::vector<ProceduralSpec>& proceduralSpecs() {
  static const std::vector<ProceduralSpec> specs = {
      {TextureDesc::Kind::Checker, 256, Vec3(0.9), Vec3(0.1), {"squares"}},
      {TextureDesc::Kind::EyeChart, 512, Vec3(1.0), Vec3(0.0), {"rows"}},
      {TextureDesc::Kind::Page, 512, Vec3(0.85, 0.82, 0.75), Vec3(0.02, 0.02, 0.025), {"lines"}},
      {TextureDesc::Kind::Bricks, 256, Vec3(0.45, 0.12, 0.07), Vec3(0.55, 0.53, 0.5), {"courses"}},
      {TextureDesc::Kind::Road, 512, Vec3(0.045, 0.045, 0.05), Vec3(0.8, 0.8, 0.75), {"lanes"}},
      {TextureDesc::Kind::Windows, 512, Vec3(0.6, 0.45, 0.32), Vec3(0.05, 0.08, 0.12), {"grid"}},
      {TextureDesc::Kind::Sky, 256, Vec3(0.75, 0.85, 1.0), Vec3(0.15, 0.3, 0.75), {}},
      {TextureDesc::Kind::Sign, 256, Vec3(0.01, 0.1, 0.5), Vec3(0.9), {"symbol"}},
  };
  return specs;
}

TextureDesc readTexture(const Ctx& c, const json* j, const std::string& path) {
  const std::string what = "an object {\"image\": \"file.png\"} or {\"procedural\": \"checker\", ...}";
  if (!j || !j->is_object()) c.expected(path, what, j);
  TextureDesc t;
  if (j->contains("image")) {
    Obj o(c, j, path, what, {"image"});
    t.kind = TextureDesc::Kind::Image;
    t.image_path = o.file("image", {".png"}, "PNG image");
    return t;
  }
  if (!j->contains("procedural")) c.expected(path, what, j);
  std::vector<std::string> names;
  for (const ProceduralSpec& s : proceduralSpecs()) names.push_back(nameOf(s.kind));
  const std::string name = peekChoice(c, j, path, what, "procedural", names);
  const ProceduralSpec& spec = *std::find_if(proceduralSpecs().begin(), proceduralSpecs().end(),
                                             [&](const ProceduralSpec& s) { return name == nameOf(s.kind); });
  std::vector<std::string> keys = {"procedural", "resolution", "seed", "a", "b"};
  keys.insert(keys.end(), spec.keys.begin(), spec.keys.end());
  Obj o(c, j, path, what, keys);
  t.kind = spec.kind;
  t.width = t.height = spec.resolution;
  if (const json* r = o.get("resolution")) {
    const std::string rwhat = "a size N or [w, h] in pixels, each in [8, " + std::to_string(kMaxTextureSize) + "]";
    if (r->is_array()) {
      if (r->size() != 2) c.expected(o.at("resolution"), rwhat, r);
      t.width = readInt(c, &(*r)[0], o.at("resolution"), 8, kMaxTextureSize);
      t.height = readInt(c, &(*r)[1], o.at("resolution"), 8, kMaxTextureSize);
    } else {
      if (!r->is_number()) c.expected(o.at("resolution"), rwhat, r);
      t.width = t.height = o.integer("resolution", 8, kMaxTextureSize);
    }
  }
  t.seed = static_cast<uint32_t>(o.number("seed", closed(0, 4294967295.0), 1, "an integer"));
  if (o.has("seed") && o.get("seed")->get<double>() != std::floor(o.get("seed")->get<double>()))
    o.expected("seed", "an integer in [0, 4294967295]");
  t.color_a = o.vec3("a", VecKind::Colour01, spec.a);
  t.color_b = o.vec3("b", VecKind::Colour01, spec.b);
  switch (spec.kind) {
    case TextureDesc::Kind::Checker: {
      t.squares_u = t.squares_v = 8;
      if (const json* s = o.get("squares")) {
        if (s->is_array()) {
          if (s->size() != 2) o.expected("squares", "a count N or [nu, nv]");
          t.squares_u = readInt(c, &(*s)[0], o.at("squares"), 1, t.width / 2);
          t.squares_v = readInt(c, &(*s)[1], o.at("squares"), 1, t.height / 2);
        } else {
          t.squares_u = o.integer("squares", 1, std::min(t.width, t.height) / 2);
          t.squares_v = t.squares_u;
        }
      }
      break;
    }
    case TextureDesc::Kind::EyeChart: {
      const int max_rows = eyeChartMaxRows(t.width, t.height);
      if (max_rows < 1) o.expected("resolution", "a resolution large enough for one row of optotypes");
      t.rows = o.integer("rows", 1, max_rows, std::min(8, max_rows));
      break;
    }
    case TextureDesc::Kind::Page: t.rows = o.integer("lines", 1, pageMaxLines(t.height), std::min(32, pageMaxLines(t.height))); break;
    case TextureDesc::Kind::Bricks: t.rows = o.integer("courses", 1, t.height / 4, std::min(8, t.height / 4)); break;
    case TextureDesc::Kind::Road: t.lanes = o.integer("lanes", 1, 8, 2); break;
    case TextureDesc::Kind::Windows: {
      if (const json* g = o.get("grid")) {
        if (!g->is_array() || g->size() != 2) o.expected("grid", "[columns, floors]");
        t.columns = readInt(c, &(*g)[0], o.at("grid"), 1, t.width / 8);
        t.floors = readInt(c, &(*g)[1], o.at("grid"), 1, t.height / 8);
      }
      break;
    }
    case TextureDesc::Kind::Sign: t.symbol = o.choice("symbol", {"arrow", "bar", "ring", "cross"}, "arrow"); break;
    case TextureDesc::Kind::Sky:
    case TextureDesc::Kind::Image: break;
  }
  return t;
}

MaterialDesc readMaterial(const Ctx& c, const json* j, const std::string& path) {
  MaterialDesc m;
  if (!j) return m;
  Obj o(c, j, path, "a material {\"color\": [r, g, b], \"texture\": {...}, \"texture_scale\": ...}",
        {"color", "texture", "texture_scale"});
  if (o.has("texture")) m.texture = readTexture(c, o.get("texture"), o.at("texture"));
  m.color = o.vec3("color", VecKind::Colour01, m.texture ? Vec3(1.0) : Vec3(0.8));
  if (const json* s = o.get("texture_scale")) {
    if (s->is_string() && s->get<std::string>() == "fit") {
      m.texture_fit = true;
    } else {
      if (!s->is_array()) o.expected("texture_scale", "\"fit\" or [su, sv] (lengths per texture repeat, each > 0)");
      m.texture_fit = false;
      m.texture_scale_m = readVec<2>(c, s, o.at("texture_scale"), VecKind::Size) * c.unit_m;
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------------------
// Sections

ObserverDesc readObserver(const Ctx& c, const json* j) {
  Obj o(c, j, "observer", "an object {\"eye\", \"target\", \"up\", \"fov_y_deg\", \"image_size\"}",
        {"eye", "target", "up", "fov_y_deg", "image_size"});
  ObserverDesc d;
  d.eye = o.point("eye");
  d.target = o.point("target");
  d.up = o.vec3("up", VecKind::Direction, Vec3(0, 1, 0));
  const Vec3 view = d.target - d.eye;
  if (glm::length(view) <= kSamePoint_m) o.expected("target", "a point different from observer.eye");
  const double a = angleBetween(d.up, view);
  if (a < kParallelAngle_rad || a > kPi - kParallelAngle_rad)
    o.expected("up", "a direction not parallel to the view direction (target - eye)");
  d.fov_y_deg = o.number("fov_y_deg", open(0, 180), 50, "an angle (degrees)");
  if (const json* s = o.get("image_size")) {
    const std::string what = "[width, height] in pixels, each in [1, " + std::to_string(kMaxImageSize) + "]";
    if (!s->is_array() || s->size() != 2) o.expected("image_size", what);
    d.image_width = readInt(c, &(*s)[0], o.at("image_size"), 1, kMaxImageSize);
    d.image_height = readInt(c, &(*s)[1], o.at("image_size"), 1, kMaxImageSize);
  }
  return d;
}

LightDesc readLight(const Ctx& c, const json* j, const std::string& path) {
  const std::string what = "a light {\"type\": " + alternatives<LightDesc::Type>() + ", ...}";
  const LightDesc::Type type = peekChoice<LightDesc::Type>(c, j, path, what, "type");
  LightDesc l;
  if (type == LightDesc::Type::Directional) {
    Obj o(c, j, path, what, {"type", "direction", "color", "intensity", "shadows", "caustics"});
    l.type = LightDesc::Type::Directional;
    l.direction = o.vec3("direction", VecKind::Direction);
    l.color = o.vec3("color", VecKind::ColourNonNegative, Vec3(1.0));
    l.intensity = o.number("intensity", kNonNegative, 1.0);
    l.shadows = o.boolean("shadows", true);
    l.caustics = o.boolean("caustics", false);
  } else if (type == LightDesc::Type::Point) {
    Obj o(c, j, path, what, {"type", "position", "color", "intensity", "shadows", "caustics"});
    l.type = LightDesc::Type::Point;
    l.position = o.point("position");
    l.color = o.vec3("color", VecKind::ColourNonNegative, Vec3(1.0));
    l.intensity = o.number("intensity", kNonNegative, 1.0);
    l.shadows = o.boolean("shadows", true);
    l.caustics = o.boolean("caustics", false);
  } else {
    Obj o(c, j, path, what, {"type", "color", "intensity"});
    l.type = LightDesc::Type::Ambient;
    l.shadows = false;
    l.color = o.vec3("color", VecKind::ColourNonNegative, Vec3(1.0));
    l.intensity = o.number("intensity", kNonNegative, 1.0);
  }
  return l;
}

// In-plane axes of a ground or quad: u from `u_hint` projected onto the plane, v = normal x u.
void planeAxes(const Obj& o, const std::string& hint_key, const Vec3& u_hint, bool hint_is_up, EnvObjectDesc& d) {
  const double a = angleBetween(u_hint, d.normal);
  if (a < kParallelAngle_rad || a > kPi - kParallelAngle_rad)
    o.ctx().expected(o.at(hint_key), "a direction not parallel to \"normal\"" +
                     std::string(o.has(hint_key) ? "" : " (the default is parallel here: give one)"),
                     o.get(hint_key));
  if (hint_is_up) {
    d.u_axis = glm::normalize(glm::cross(u_hint, d.normal));
  } else {
    d.u_axis = glm::normalize(u_hint - glm::dot(u_hint, d.normal) * d.normal);
  }
  d.v_axis = glm::cross(d.normal, d.u_axis);
}

// --- animation ---

// {"interpolation": "linear" | "smooth", "keys": [{"time_s", "offset", "rotation_deg"}, ...]}: at least one
// key, times finite and strictly increasing; offsets in the file's unit.
AnimationDesc readAnimation(const Ctx& c, const json* j, const std::string& path) {
  Obj o(c, j, path, "an animation {\"interpolation\": " + alternatives<Interpolation>() + ", \"keys\": [...]}",
        {"interpolation", "keys"});
  AnimationDesc a;
  a.interpolation = o.choice<Interpolation>("interpolation", Interpolation::Linear);
  const json* keys = o.get("keys");
  const std::string what = "a non-empty array of keys [{\"time_s\", \"offset\", \"rotation_deg\"}, ...]";
  if (!keys || !keys->is_array() || keys->empty()) o.expected("keys", what);
  for (size_t i = 0; i < keys->size(); ++i) {
    const std::string kp = indexPath(o.at("keys"), i);
    Obj k(c, &(*keys)[i], kp, "a key {\"time_s\": seconds, \"offset\": [x, y, z], \"rotation_deg\": [x, y, z]}",
          {"time_s", "offset", "rotation_deg"});
    Keyframe key;
    key.time_s = k.number("time_s", kAny, "a time in seconds");
    if (!a.keys.empty() && !(key.time_s > a.keys.back().time_s))
      c.fail(k.at("time_s"), "expected a time after the previous key's " + fmt(a.keys.back().time_s) + " s, got " +
                                 show(k.get("time_s")));
    key.offset_m = k.point("offset", Vec3(0));
    key.rotation_deg = k.vec3("rotation_deg", VecKind::Point, Vec3(0));
    a.keys.push_back(key);
  }
  return a;
}

// "animation" and "dynamic" of an environment object or element.
void readMotion(const Ctx& c, const Obj& o, std::optional<AnimationDesc>& animation, bool& dynamic) {
  if (o.has("animation")) animation = readAnimation(c, o.get("animation"), o.at("animation"));
  dynamic = o.boolean("dynamic", animation.has_value());
  if (animation && !dynamic) o.expected("dynamic", "true (an animated object is dynamic) or no \"dynamic\"");
}

EnvObjectDesc readEnvObject(const Ctx& c, const json* j, const std::string& path, size_t index) {
  const std::string what = "an environment object {\"type\": " + alternatives<EnvObjectDesc::Type>() + ", ...}";
  using Type = EnvObjectDesc::Type;
  const Type type = peekChoice<Type>(c, j, path, what, "type");
  std::vector<std::string> keys = {"type", "name", "material", "animation", "dynamic", "ambient_occlusion"};
  if (type == Type::Mesh) keys.insert(keys.end(), {"file", "transform"});
  if (type == Type::Ground) keys.insert(keys.end(), {"point", "normal", "size", "u_axis"});
  if (type == Type::Box) keys.insert(keys.end(), {"centre", "size", "rotation_deg", "axis_angle"});
  if (type == Type::Sphere) keys.insert(keys.end(), {"centre", "radius"});
  if (type == Type::Quad) keys.insert(keys.end(), {"centre", "normal", "up", "size"});
  Obj o(c, j, path, what, keys);
  EnvObjectDesc d;
  d.name = o.string("name", nameOf(type) + std::to_string(index));
  d.material = readMaterial(c, o.get("material"), o.at("material"));
  d.type = type;
  readMotion(c, o, d.animation, d.dynamic);
  if (const json* a = o.get("ambient_occlusion")) {
    if (a->is_boolean()) d.occluder = a->get<bool>() ? "object:" + std::to_string(index) : "";
    else if (a->is_string() && !a->get<std::string>().empty()) d.occluder = "group:" + a->get<std::string>();
    else o.expected("ambient_occlusion", "true, false or a group name (objects that move together)");
  }
  if (type == Type::Mesh) {
    d.file = o.file("file", {".obj", ".ply", ".gltf", ".glb", ".stl"}, "OBJ, PLY, glTF or STL mesh");
    d.scale = Vec3(c.unit_m);
    if (o.has("transform")) {
      Obj t(c, o.get("transform"), o.at("transform"),
            "a transform {\"position\", \"rotation_deg\" | \"axis_angle\", \"scale\"}",
            {"position", "rotation_deg", "axis_angle", "scale"});
      d.position = t.point("position", Vec3(0));
      d.rotation = readRotation(t);
      if (const json* s = t.get("scale")) {
        if (s->is_array()) d.scale = readVec<3>(c, s, t.at("scale"), VecKind::Positive) * c.unit_m;
        else d.scale = Vec3(t.number("scale", kPositive)) * c.unit_m;
      }
    }
  } else if (type == Type::Ground || type == Type::Quad) {
    d.position = o.point(type == Type::Ground ? "point" : "centre");
    d.normal = o.vec3("normal", VecKind::Direction);
    d.size = Vec3(o.vec2("size", VecKind::Size) * c.unit_m, 0.0);
    if (type == Type::Ground) {
      const Vec3 hint = o.has("u_axis") ? o.vec3("u_axis", VecKind::Direction)
                        : (std::abs(d.normal.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 0, -1));
      planeAxes(o, "u_axis", hint, false, d);
    } else {
      planeAxes(o, "up", o.vec3("up", VecKind::Direction, Vec3(0, 1, 0)), true, d);
    }
  } else if (type == Type::Box) {
    d.position = o.point("centre");
    d.size = o.vec3("size", VecKind::Size) * c.unit_m;
    d.rotation = readRotation(o);
  } else {
    d.position = o.point("centre");
    d.radius_m = o.length("radius", kPositive);
  }
  return d;
}

// --- elements ---

bool anySurface(SurfaceDesc::Type) { return true; }
// A lens surface: analytic, or a CAD face that is a graph over the lens plane (cad::makeNurbsSag).
bool lensSurface(SurfaceDesc::Type t) { return t != SurfaceDesc::Type::Subdivision; }

double nonZeroRadius(const Obj& o, const std::string& k) {
  const double r = o.number(k, kAny, "a length");
  if (r == 0)
    o.expected(k, "a non-zero radius (R > 0 convex, R < 0 concave as seen from +z; a flat surface is "
                  "{\"type\": \"plane\"})");
  return r * o.ctx().unit_m;
}

// `allowed`: the surface types accepted here (anySurface, lensSurface).
SurfaceDesc readSurface(const Ctx& c, const json* j, const std::string& path, bool (*allowed)(SurfaceDesc::Type)) {
  using Type = SurfaceDesc::Type;
  const std::string what = "a surface {\"type\": ...}";
  const Type type = peekChoice<Type>(c, j, path, what, "type", allowed);
  SurfaceDesc s;
  s.type = type;
  if (type == Type::Plane) {
    Obj o(c, j, path, what, {"type"});
  } else if (type == Type::Sphere) {
    Obj o(c, j, path, what, {"type", "radius"});
    s.radius_m = nonZeroRadius(o, "radius");
  } else if (type == Type::Asphere) {
    Obj o(c, j, path, what, {"type", "radius", "conic", "coefficients"});
    s.radius_m = nonZeroRadius(o, "radius");
    s.conic = o.number("conic", kAny, 0.0);
    if (const json* a = o.get("coefficients")) {
      if (!a->is_array()) o.expected("coefficients", "an array [A4, A6, ...] of finite numbers");
      for (size_t i = 0; i < a->size(); ++i) {
        const double v = readNumber(c, &(*a)[i], indexPath(o.at("coefficients"), i), kAny);
        // A term A r^n with r and sag in the file unit s (metres per unit): A_m = A s^(1 - n).
        const int n = static_cast<int>(2 * i + 4);
        s.coefficients.push_back(v * std::pow(c.unit_m, 1 - n));
      }
    }
  } else if (type == Type::Toric) {
    Obj o(c, j, path, what, {"type", "radius_a", "radius_b", "axis_deg"});
    s.radius_a_m = nonZeroRadius(o, "radius_a");
    s.radius_b_m = nonZeroRadius(o, "radius_b");
    s.axis_deg = o.number("axis_deg", closed(-360, 360), 0.0, "an angle (degrees)");
  } else if (type == Type::Cylinder) {
    Obj o(c, j, path, what, {"type", "radius", "axis_deg"});
    s.radius_m = nonZeroRadius(o, "radius");
    s.axis_deg = o.number("axis_deg", closed(-360, 360), 0.0, "an angle (degrees)");
  } else if (type == Type::Cad) {
    Obj o(c, j, path, what, {"type", "file", "face"});
    s.file = o.file("file", {".step", ".stp", ".igs", ".iges"}, "STEP or IGES file");
    s.face = o.integer("face", 0, INT_MAX, 0);
  } else {
    Obj o(c, j, path, what, {"type", "file"});
    s.file = o.file("file", {".obj"}, "OBJ quad cage");
    s.file_unit_m = c.unit_m;
  }
  return s;
}

// Largest distance from the vertex to the outline (metres).
double outlineReach_m(const OutlineDesc& o) {
  switch (o.shape) {
    case OutlineDesc::Shape::Rectangle: {
      const double r = o.corner_radius_m;
      return glm::length(Vec2(0.5 * o.width_m - r, 0.5 * o.height_m - r)) + r;
    }
    case OutlineDesc::Shape::Ellipse:
    case OutlineDesc::Shape::Circle: return 0.5 * std::max(o.width_m, o.height_m);
  }
  return 0;
}

// A sag surface must be defined over its outline (cad/sag.h): |R| beyond the outline's reach for spheres
// and the sections of toric and cylindrical surfaces (conservatively, in every direction), and
// (1 + k) r^2 < R^2 for a conic.
void checkSagReach(const Ctx& c, const json& surface_json, const std::string& path, const SurfaceDesc& s,
                   const OutlineDesc& outline) {
  const double reach = outlineReach_m(outline);
  const auto need = [&](const char* key, double radius_m, double factor) {
    if (std::abs(radius_m) * factor > reach) return;
    const double limit = reach / factor / c.unit_m;
    c.expected(childPath(path, key),
               "|" + std::string(key) + "| > " + fmt(limit) + " " + c.units + " (the outline reaches " +
                   fmt(reach / c.unit_m) + " " + c.units + " from the vertex" +
                   (factor != 1 ? ", with the conic constant" : "") + ")",
               &surface_json.at(key));
  };
  switch (s.type) {
    case SurfaceDesc::Type::Sphere:
    case SurfaceDesc::Type::Cylinder: need("radius", s.radius_m, 1); break;
    case SurfaceDesc::Type::Asphere:
      if (1 + s.conic > 0) need("radius", s.radius_m, 1 / std::sqrt(1 + s.conic));
      break;
    case SurfaceDesc::Type::Toric:
      need("radius_a", s.radius_a_m, 1);
      need("radius_b", s.radius_b_m, 1);
      break;
    default: break;
  }
}

OutlineDesc readOutline(const Ctx& c, const json* j, const std::string& path) {
  const std::string what = "an outline {\"shape\": " + alternatives<OutlineDesc::Shape>() + ", ...}";
  using Shape = OutlineDesc::Shape;
  OutlineDesc d;
  d.shape = peekChoice<Shape>(c, j, path, what, "shape");
  if (d.shape == Shape::Circle) {
    Obj o(c, j, path, what, {"shape", "diameter"});
    d.width_m = d.height_m = o.length("diameter", kPositive);
  } else if (d.shape == Shape::Ellipse) {
    Obj o(c, j, path, what, {"shape", "width", "height"});
    d.width_m = o.length("width", kPositive);
    d.height_m = o.length("height", kPositive);
  } else {
    Obj o(c, j, path, what, {"shape", "width", "height", "corner_radius"});
    d.width_m = o.length("width", kPositive);
    d.height_m = o.length("height", kPositive);
    const double half_min = 0.5 * std::min(d.width_m, d.height_m) / c.unit_m;
    d.corner_radius_m = o.length("corner_radius", closed(0, half_min), 0.0);
  }
  return d;
}

TessellationDesc readTessellation(const Ctx& c, const json* j, const std::string& path, int default_n) {
  TessellationDesc t;
  t.n_u = t.n_v = default_n;
  if (!j) return t;
  const std::string what = "a vertex count N in [2, 1024], {\"u\": N, \"v\": M} or {\"tolerance\": length, "
                           "\"angle_deg\": a}";
  if (j->is_number()) {
    t.n_u = t.n_v = readInt(c, j, path, 2, 1024);
    return t;
  }
  Obj o(c, j, path, what, {"u", "v", "tolerance", "angle_deg"});
  const bool grid = o.has("u") || o.has("v"), adaptive = o.has("tolerance") || o.has("angle_deg");
  if (grid == adaptive) c.expected(path, what, j);
  if (grid) {
    t.n_u = o.integer("u", 2, 1024);
    t.n_v = o.integer("v", 2, 1024);
  } else {
    t.mode = TessellationDesc::Mode::Adaptive;
    t.chordal_tolerance_m = o.length("tolerance", kPositive);
    t.angle_tolerance_deg = o.number("angle_deg", leftOpen(0, 90), 5.0, "an angle (degrees)");
  }
  return t;
}

MirrorMaterialDesc readMirrorMaterial(const Ctx& c, const json* j, const std::string& path) {
  MirrorMaterialDesc m;
  if (!j) return m;
  const std::string what = "a mirror material {\"reflectance\": x} | {\"metal\": name} | {\"n\": [r, g, b], "
                           "\"k\": [r, g, b]}";
  Obj o(c, j, path, what, {"reflectance", "metal", "n", "k"});
  const int forms = int(o.has("reflectance")) + int(o.has("metal")) + int(o.has("n") || o.has("k"));
  if (forms != 1) c.expected(path, "exactly one of {\"reflectance\"}, {\"metal\"} or {\"n\", \"k\"}", j);
  if (o.has("reflectance")) {
    m.kind = MirrorMaterialDesc::Kind::Reflectance;
    m.reflectance = o.number("reflectance", leftOpen(0, 1));
  } else if (o.has("metal")) {
    m.kind = MirrorMaterialDesc::Kind::Metal;
    m.metal = o.choice("metal", metalNames());  // pvrr/optics/material.h
  } else {
    m.kind = MirrorMaterialDesc::Kind::Conductor;
    m.n = o.vec3("n", VecKind::Positive);
    m.k = o.vec3("k", VecKind::ColourNonNegative);
  }
  return m;
}

LensMaterialDesc readLensMaterial(const Ctx& c, const json* j, const std::string& path) {
  const std::string what = "a lens material {\"name\": ...} | {\"n_d\": ..., \"V_d\": ...} | "
                           "{\"sellmeier\": {\"B\": [3], \"C\": [3]}}";
  Obj o(c, j, path, what,
        {"name", "n_d", "V_d", "sellmeier", "dispersion", "internal_transmittance", "internal_transmittance_thickness"});
  LensMaterialDesc m;
  const int forms = int(o.has("name")) + int(o.has("n_d") || o.has("V_d")) + int(o.has("sellmeier"));
  if (forms != 1)
    c.expected(path,
               "exactly one of {\"name\"}, {\"n_d\", \"V_d\"} or {\"sellmeier\"} (plus \"dispersion\", "
               "\"internal_transmittance\", \"internal_transmittance_thickness\")",
               j);
  if (o.has("name")) {
    // The material library (pvrr/optics/material.h) is the catalogue: its names, its n_d and V_d.
    m.kind = LensMaterialDesc::Kind::Named;
    m.name = o.choice("name", lensMaterialNames());
    const Dispersion d = lookupLensMaterial(m.name).dispersion;
    m.n_d = d.n_d();
    m.V_d = d.abbe();
  } else if (o.has("sellmeier")) {
    m.kind = LensMaterialDesc::Kind::Sellmeier;
    Obj s(c, o.get("sellmeier"), o.at("sellmeier"), "an object {\"B\": [B1, B2, B3], \"C\": [C1, C2, C3] (um^2)}",
          {"B", "C"});
    const Vec3 b = s.vec3("B", VecKind::ColourNonNegative), cc = s.vec3("C", VecKind::ColourNonNegative);
    for (int i = 0; i < 3; ++i) {
      m.sellmeier_b[i] = b[i];
      m.sellmeier_c_um2[i] = cc[i];
    }
    const std::string what = "coefficients giving a finite index > 1 with normal dispersion over " +
                             fmt(kDispersionCheckMin_nm) + ".." + fmt(kDispersionCheckMax_nm) + " nm";
    try {
      const Dispersion d = Dispersion::sellmeier(m.sellmeier_b, m.sellmeier_c_um2);
      m.n_d = d.n_d();
      m.V_d = d.abbe();
    } catch (const Error&) {
      c.expected(s.path(), what, o.get("sellmeier"));
    }
    if (!(m.n_d > 1) || !(m.V_d > 0) || !std::isfinite(m.V_d)) c.expected(s.path(), what, o.get("sellmeier"));
  } else {
    m.kind = LensMaterialDesc::Kind::Abbe;
    m.n_d = o.number("n_d", leftOpen(1, 3));
    m.V_d = o.number("V_d", closed(10, 120));
  }
  m.dispersion = o.boolean("dispersion", true);
  // Absorption: tau_i as one number (grey) or [r, g, b], each in (0, 1], over a reference path (a length in the
  // file's unit, default 10 mm as glass catalogues quote it).
  if (o.has("internal_transmittance")) {
    const json* t = o.get("internal_transmittance");
    const std::string twhat = "an internal transmittance in (0, 1] or [r, g, b] with each in (0, 1]";
    const Range unit = leftOpen(0, 1);
    if (t->is_array()) {
      if (t->size() != 3) o.expected("internal_transmittance", twhat);
      for (int i = 0; i < 3; ++i) {
        const json& e = (*t)[size_t(i)];
        if (!e.is_number() || !std::isfinite(e.get<double>()) || !unit.contains(e.get<double>()))
          o.expected("internal_transmittance", twhat);
        m.internal_transmittance[i] = e.get<double>();
      }
    } else {
      if (!t->is_number()) o.expected("internal_transmittance", twhat);
      m.internal_transmittance = Vec3(o.number("internal_transmittance", unit, "an internal transmittance"));
    }
  }
  m.internal_transmittance_thickness_m =
      o.length("internal_transmittance_thickness", kPositive, kInternalTransmittanceThickness_m);
  return m;
}

// A lens's `eye` block: {"rotation_centre": length > 0}, the eye's centre of rotation behind the eye-side vertex.
double readEyeRotationCentre(const Ctx& c, const json* j, const std::string& path) {
  Obj o(c, j, path, "an eye {\"rotation_centre\": a length behind the eye-side vertex}", {"rotation_centre"});
  return o.length("rotation_centre", kPositive, kDefaultEyeRotationCentre_m);
}

ElementDesc readElement(const Ctx& c, const json* j, const std::string& path, size_t index) {
  const std::string what = "an element {\"type\": " + alternatives<ElementDesc::Type>() + ", ...}";
  const ElementDesc::Type type = peekChoice<ElementDesc::Type>(c, j, path, what, "type");
  std::vector<std::string> keys = {"name",     "type",         "pose",    "attached_to_observer",
                                   "outline",  "tessellation", "patches", "max_patch_fov_deg",
                                   "material", "animation",    "dynamic"};
  if (type == ElementDesc::Type::Mirror) keys.insert(keys.end(), {"surface", "pivot"});
  else keys.insert(keys.end(), {"front", "back", "centre_thickness", "min_edge_thickness", "prescription", "eye"});
  Obj o(c, j, path, what, keys);
  ElementDesc e;
  e.type = type;
  e.name = o.string("name", "element" + std::to_string(index));
  e.attached_to_observer = o.boolean("attached_to_observer", false);
  readMotion(c, o, e.animation, e.dynamic);

  {
    Obj p(c, o.get("pose"), o.at("pose"), "a pose {\"position\", \"normal\", \"up\"}", {"position", "normal", "up"});
    e.pose.position = p.point("position");
    e.pose.normal = p.vec3("normal", VecKind::Direction);
    e.pose.up = p.vec3("up", VecKind::Direction, Vec3(0, 1, 0));
    const double a = angleBetween(e.pose.up, e.pose.normal);
    if (a < kParallelAngle_rad || a > kPi - kParallelAngle_rad)
      p.expected("up", "a direction not parallel to \"normal\"" +
                           std::string(p.has("up") ? "" : " (the default [0, 1, 0] is parallel here: give one)"));
  }

  // Surfaces first: whether an outline is required depends on them.
  bool analytic = true;
  if (e.type == ElementDesc::Type::Mirror) {
    e.surface = readSurface(c, o.get("surface"), o.at("surface"), anySurface);
    analytic = e.surface.isSag();
    e.mirror_material = readMirrorMaterial(c, o.get("material"), o.at("material"));
    if (o.has("pivot")) e.pivot = o.point("pivot");
  } else {
    if (o.has("prescription") && (o.has("front") || o.has("back")))
      o.expected("prescription", "either \"prescription\" or \"front\" and \"back\", not both");
    if (o.has("prescription")) {
      Obj p(c, o.get("prescription"), o.at("prescription"),
            "a prescription {\"sphere_d\", \"cylinder_d\", \"axis_deg\", \"base_curve_d\"}",
            {"sphere_d", "cylinder_d", "axis_deg", "base_curve_d"});
      PrescriptionDesc rx;
      rx.sphere_d = p.number("sphere_d", closed(-30, 30), "a power in dioptres");
      rx.cylinder_d = p.number("cylinder_d", closed(-15, 15), 0.0, "a power in dioptres");
      rx.axis_deg = p.number("axis_deg", closed(0, 180), 0.0, "an angle (degrees)");
      if (p.has("base_curve_d")) rx.base_curve_d = p.number("base_curve_d", leftOpen(0, 25), "a power in dioptres");
      e.prescription = rx;
    } else {
      e.front = readSurface(c, o.get("front"), o.at("front"), lensSurface);
      e.back = readSurface(c, o.get("back"), o.at("back"), lensSurface);
    }
    if (!o.has("centre_thickness") && !o.has("min_edge_thickness"))
      o.expected("centre_thickness", "a length > 0 (or \"min_edge_thickness\")");
    e.centre_thickness_m = o.length("centre_thickness", kPositive, 0.0);
    e.min_edge_thickness_m = o.length("min_edge_thickness", kPositive, 0.0);
    e.lens_material = readLensMaterial(c, o.get("material"), o.at("material"));
    if (o.has("eye")) e.eye_rotation_centre_m = readEyeRotationCentre(c, o.get("eye"), o.at("eye"));
  }

  if (analytic) {
    e.outline = readOutline(c, o.get("outline"), o.at("outline"));
    if (e.type == ElementDesc::Type::Mirror) {
      checkSagReach(c, *o.get("surface"), o.at("surface"), e.surface, *e.outline);
    } else if (!e.prescription) {
      checkSagReach(c, *o.get("front"), o.at("front"), e.front, *e.outline);
      checkSagReach(c, *o.get("back"), o.at("back"), e.back, *e.outline);
    }
  } else if (o.has("outline")) {
    o.expected("outline", std::string("no outline with a \"") + nameOf(e.surface.type) +
                              "\" surface (its own boundary is the outline)");
  }

  e.tessellation = readTessellation(c, o.get("tessellation"), o.at("tessellation"),
                                    e.type == ElementDesc::Type::Mirror ? 7 : 24);
  if (const json* p = o.get("patches")) {
    const bool grid = e.tessellation.mode == TessellationDesc::Mode::Grid;
    const int max_u = grid ? e.tessellation.n_u - 1 : 1, max_v = grid ? e.tessellation.n_v - 1 : 1;
    const std::string pwhat = "[pu, pv] with 1 <= pu <= " + std::to_string(max_u) + " and 1 <= pv <= " +
                              std::to_string(max_v) + (grid ? " (each patch at least one grid cell)"
                                                             : " (an adaptive tessellation is not split)");
    if (!p->is_array() || p->size() != 2) o.expected("patches", pwhat);
    for (int i = 0; i < 2; ++i)
      if (!(*p)[i].is_number() || (*p)[i].get<double>() != std::floor((*p)[i].get<double>()) ||
          (*p)[i].get<double>() < 1 || (*p)[i].get<double>() > (i == 0 ? max_u : max_v))
        o.expected("patches", pwhat);
    e.patches_u = (*p)[0].get<int>();
    e.patches_v = (*p)[1].get<int>();
  }
  e.max_patch_fov_deg = o.number("max_patch_fov_deg", open(0, 180), kDefaultMaxPatchFovDeg, "an angle (degrees)");
  return e;
}

// render.ambient_occlusion: true, false, or {"positions", "directions", "reference_samples"} (on).
AmbientOcclusionDesc readAmbientOcclusion(const Ctx& c, const Obj& render) {
  AmbientOcclusionDesc a;
  const json* j = render.get("ambient_occlusion");
  if (j->is_boolean()) {
    a.on = j->get<bool>();
    return a;
  }
  Obj o(c, j, render.at("ambient_occlusion"),
        "true, false or an object {\"positions\", \"directions\", \"reference_samples\"}",
        {"positions", "directions", "reference_samples"});
  a.on = true;
  a.positions = o.integer("positions", 4, 128, a.positions);
  a.directions = o.integer("directions", 4, 64, a.directions);
  a.reference_samples = o.integer("reference_samples", 1, 4096, a.reference_samples);
  return a;
}

RenderDesc readRender(const Ctx& c, const json* j, const std::string& source) {
  RenderDesc r;  // its defaults are the format's
  r.output = (fs::path("out") / (fs::path(source).stem().string() + ".png")).string();
  if (!j) return r;
  Obj o(c, j, "render", "an object {\"mode\", \"map_size\", \"output\", ...}",
        {"mode", "map_size", "map_texels_per_pixel", "map_reuse_margin_deg", "impostor_iterations", "impostor_layers", "refine", "output",
         "max_depth", "dispersion", "spectral_samples",
         "background", "viewpoint_solver", "ambient_occlusion"});
  r.mode = o.choice<RenderMode>("mode", r.mode);
  r.map_size = o.integer("map_size", 16, kMaxImageSize, r.map_size);
  r.map_texels_per_pixel = o.number("map_texels_per_pixel", closed(0, 1e4), r.map_texels_per_pixel);
  r.map_reuse_margin_deg = o.number("map_reuse_margin_deg", closed(0, 10), r.map_reuse_margin_deg);
  r.impostor_iterations = o.integer("impostor_iterations", 0, 64, r.impostor_iterations);
  r.impostor_layers = o.integer("impostor_layers", 1, 2, r.impostor_layers);
  if (o.has("refine")) {
    const json* v = o.get("refine");
    const bool off = v->is_string() && v->get<std::string>() == "off";
    const bool steps = v->is_number_integer() && v->get<int64_t>() >= 1 && v->get<int64_t>() <= kMaxRefineSteps;
    if (!off && !steps) o.expected("refine", "\"off\" or an integer in [1, " + std::to_string(kMaxRefineSteps) + "]");
    r.refine = off ? 0 : int(v->get<int64_t>());
  }
  if (o.has("output")) {
    r.output = o.string("output");
    if (!endsWithAny(r.output, {".png"})) o.expected("output", "a file name ending in \".png\"");
  }
  r.max_depth = o.integer("max_depth", 1, kMaxDepthLimit, r.max_depth);
  r.dispersion = o.choice<DispersionMode>("dispersion", r.dispersion);
  r.spectral_samples = o.integer("spectral_samples", 3, 256, r.spectral_samples);
  r.background = o.vec3("background", VecKind::ColourNonNegative, r.background);
  r.viewpoint_solver = o.choice<ViewpointSolver>("viewpoint_solver", r.viewpoint_solver);
  if (o.has("ambient_occlusion")) r.ambient_occlusion = readAmbientOcclusion(c, o);
  return r;
}

}  // namespace

SceneDesc readScene(Ctx& c, const json& doc) {
  Obj top(c, &doc, "", "a JSON object (a scene)",
          {"version", "units", "description", "observer", "environment", "lights", "elements", "render", "vehicle"});
  SceneDesc s;
  {
    const json* v = top.get("version");
    if (!v || !v->is_number() || v->get<double>() != 1)
      top.expected("version", "1 (the only scene format version this pvrr reads)");
  }
  s.units = top.choice("units", {"m", "mm"}, "m");
  s.unit_m = s.units == "mm" ? 1e-3 : 1.0;
  c.units = s.units;
  c.unit_m = s.unit_m;
  s.source = c.file;
  s.base_dir = c.base_dir;
  if (top.has("description") && !top.get("description")->is_string()) top.expected("description", "a string");
  s.description = top.has("description") ? top.get("description")->get<std::string>() : "";
  s.observer = readObserver(c, top.get("observer"));

  if (const json* env = arrayAt(c, top.get("environment"), "environment", "an array of environment objects"))
    for (size_t i = 0; i < env->size(); ++i)
      s.environment.push_back(readEnvObject(c, &(*env)[i], indexPath("environment", i), i));

  if (const json* lights = arrayAt(c, top.get("lights"), "lights", "an array of lights")) {
    for (size_t i = 0; i < lights->size(); ++i) s.lights.push_back(readLight(c, &(*lights)[i], indexPath("lights", i)));
    // The raster shaders hold each kind in a uniform array (shaders/shading.glsl).
    size_t dir = 0, point = 0;
    for (const LightDesc& l : s.lights) {
      dir += l.type == LightDesc::Type::Directional;
      point += l.type == LightDesc::Type::Point;
    }
    if (dir > kMaxLightsPerKind || point > kMaxLightsPerKind)
      c.fail("lights", "expected at most " + std::to_string(kMaxLightsPerKind) + " directional and " +
                           std::to_string(kMaxLightsPerKind) + " point lights, got " + std::to_string(dir) +
                           " directional and " + std::to_string(point) + " point");
  } else {
    s.lights.push_back(LightDesc{});  // no "lights": ambient white, intensity 1 (albedo shown as is)
  }

  if (const json* els = arrayAt(c, top.get("elements"), "elements", "an array of elements")) {
    std::set<std::string> names;
    for (size_t i = 0; i < els->size(); ++i) {
      const std::string path = indexPath("elements", i);
      s.elements.push_back(readElement(c, &(*els)[i], path, i));
      if (!names.insert(s.elements.back().name).second)
        c.expected(childPath(path, "name"), "a name no other element has (names default to \"element<index>\")",
                   (*els)[i].contains("name") ? &(*els)[i]["name"] : nullptr);
    }
  }
  s.render = readRender(c, top.get("render"), c.file);
  if (top.has("vehicle")) s.vehicle = readVehicle(c, top.get("vehicle"), s.environment);
  return s;
}

}  // namespace pvrr::scene_json_detail

#include "app/fov_regulation.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pvrr/base/error.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

namespace {

struct Reader {
  std::string file;
  [[noreturn]] void fail(const std::string& path, const std::string& msg) const {
    throw Error(file + ": " + path + ": " + msg);
  }
  const json& at(const json& o, const std::string& key, const std::string& path) const {
    if (!o.is_object() || !o.contains(key)) fail(path, "missing \"" + key + "\"");
    return o[key];
  }
  std::string string(const json& o, const std::string& key, const std::string& path) const {
    const json& j = at(o, key, path);
    if (!j.is_string()) fail(path + "." + key, "expected a string");
    return j.get<std::string>();
  }
  // A sourced value {"value", "source", "verified"[, "note"]}; `verified` collects the flags.
  const json& sourced(const json& o, const std::string& key, const std::string& path, bool& verified) const {
    const std::string p = path + "." + key;
    const json& j = at(o, key, path);
    if (!j.is_object() || !j.contains("value") || !j.contains("source") || !j["source"].is_string() ||
        !j.contains("verified") || !j["verified"].is_boolean())
      fail(p, "expected {\"value\", \"source\": string, \"verified\": true or false}");
    verified = verified && j["verified"].get<bool>();
    return j["value"];
  }
  double number(const json& o, const std::string& key, const std::string& path, bool& verified, double lo,
                double hi) const {
    const json& v = sourced(o, key, path, verified);
    if (!v.is_number() || v.get<double>() < lo || v.get<double>() > hi)
      fail(path + "." + key + ".value",
           "expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.get<double>();
  }
};

std::vector<std::string> known(const std::vector<std::string>& folders) {
  std::vector<std::string> ids;
  for (const std::string& f : folders) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(f, ec))
      if (e.path().extension() == ".json") ids.push_back(e.path().stem().string());
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

}  // namespace

Regulation loadRegulation(const std::string& id, const std::vector<std::string>& folders) {
  std::string path;
  if (id.size() > 5 && id.substr(id.size() - 5) == ".json") {
    path = id;
  } else {
    for (const std::string& f : folders)
      if (fs::is_regular_file(fs::path(f) / (id + ".json"))) {
        path = (fs::path(f) / (id + ".json")).string();
        break;
      }
  }
  if (path.empty() || !fs::is_regular_file(path)) {
    std::string list;
    for (const std::string& k : known(folders)) list += (list.empty() ? "" : ", ") + k;
    throw Error("pvrr fov: unknown regulation \"" + id + "\"" + (list.empty() ? "" : " (known: " + list + ")"));
  }
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const Reader r{path};
  json doc;
  try {
    doc = json::parse(ss.str());
  } catch (const json::parse_error& e) {
    throw Error(path + ": syntax error: " + e.what());
  }
  Regulation reg;
  reg.path = path;
  reg.id = r.string(doc, "id", "(top level)");
  reg.title = r.string(doc, "title", "(top level)");
  reg.document = r.string(doc, "document", "(top level)");
  const std::string side = r.string(doc, "side", "(top level)");
  if (side != "driver" && side != "passenger") r.fail("side", "expected \"driver\" or \"passenger\"");
  reg.driver_side = side == "driver";
  reg.verified = true;
  const json& zones = r.at(doc, "zones", "(top level)");
  if (!zones.is_array() || zones.empty()) r.fail("zones", "expected a non-empty array of zones");
  for (size_t i = 0; i < zones.size(); ++i) {
    const std::string p = "zones[" + std::to_string(i) + "]";
    const json& z = zones[i];
    FovZone fz;
    fz.regulation = reg.id;
    fz.name = r.string(z, "name", p);
    fz.driver_side = reg.driver_side;
    bool ok = true;
    const json& eyes = r.sourced(z, "eyes", p, ok);
    const std::string e = eyes.is_string() ? eyes.get<std::string>() : "";
    if (e == "either")
      fz.eyes = FovZone::Eyes::Either;
    else if (e == "both")
      fz.eyes = FovZone::Eyes::Both;
    else if (e == "left")
      fz.eyes = FovZone::Eyes::Left;
    else if (e == "right")
      fz.eyes = FovZone::Eyes::Right;
    else
      r.fail(p + ".eyes.value", "expected \"either\", \"both\", \"left\" or \"right\"");
    const double from = r.number(z, "from_behind_m", p, ok, 0, 1e4);
    double to = -kInf;
    const json& t = r.at(z, "to", p);
    if (t.is_string() && t.get<std::string>() == "horizon") {
      to = -kInf;
    } else {
      to = -r.number(z, "to", p, ok, from, 1e4);
    }
    const double inner = r.number(z, "inner_m", p, ok, -100, 100);
    const double width = r.number(z, "width_m", p, ok, 1e-3, 100);
    fz.allowed_obstructed_fraction = r.number(z, "allowed_obstructed_fraction", p, ok, 0, 1);
    fz.polygon = {Vec2(-from, inner), Vec2(-from, inner + width), Vec2(to, inner + width), Vec2(to, inner)};
    fz.verified = ok;
    fz.source = reg.title;
    reg.verified = reg.verified && ok;
    reg.zones.push_back(fz);
  }
  if (doc.contains("mirror")) {
    const json& m = doc["mirror"];
    if (!m.is_array()) r.fail("mirror", "expected an array of requirements");
    for (size_t i = 0; i < m.size(); ++i) {
      const std::string p = "mirror[" + std::to_string(i) + "]";
      MirrorRequirement q;
      q.name = r.string(m[i], "name", p);
      q.meaning = r.string(m[i], "meaning", p);
      q.source = r.string(m[i], "source", p);
      if (!m[i].contains("value") || !m[i]["value"].is_number()) r.fail(p + ".value", "expected a number");
      q.value = m[i]["value"].get<double>();
      if (!m[i].contains("verified") || !m[i]["verified"].is_boolean())
        r.fail(p + ".verified", "expected true or false");
      q.verified = m[i]["verified"].get<bool>();
      if (m[i].contains("note") && m[i]["note"].is_string()) q.note = m[i]["note"].get<std::string>();
      reg.verified = reg.verified && q.verified;
      reg.mirror.push_back(q);
    }
  }
  return reg;
}

}  // namespace pvrr::app

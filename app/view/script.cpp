#include "app/view/script.h"

#define GLFW_INCLUDE_NONE  // the key codes only
#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "app/args.h"
#include "pvrr/base/error.h"

namespace pvrr::app::view {
namespace {

using nlohmann::json;

// The `do` values and the keys each takes besides "at_frame" and "do".
const std::map<std::string, std::pair<EventKind, std::vector<std::string>>>& kinds() {
  static const std::map<std::string, std::pair<EventKind, std::vector<std::string>>> table = {
      {"set", {EventKind::Set, {"path", "value"}}},
      {"turn_head", {EventKind::TurnHead, {"yaw_deg", "pitch_deg"}}},
      {"move_eye", {EventKind::MoveEye, {"by"}}},
      {"screenshot", {EventKind::Screenshot, {"file", "panel"}}},
      {"save_view", {EventKind::SaveView, {"file"}}},
      {"quit", {EventKind::Quit, {}}},
      {"key", {EventKind::Key, {"key", "shift"}}},
      {"reference", {EventKind::Reference, {}}},
      {"wipe", {EventKind::Wipe, {"x"}}},
      {"overlay", {EventKind::Overlay, {"on"}}},
      {"drag", {EventKind::Drag, {"button", "from", "to"}}},
      {"turn_element", {EventKind::TurnElement, {"element", "yaw_deg", "pitch_deg"}}},
      {"cursor", {EventKind::Cursor, {"at"}}},
      {"move_element", {EventKind::MoveElement, {"element", "by"}}},
      {"time", {EventKind::Time, {"t", "play"}}},
  };
  return table;
}

// The keys the viewer answers to, by their GLFW names (GLFW_KEY_<name>).
const std::map<std::string, int>& keyCodes() {
  static const std::map<std::string, int> table = {
      {"W", GLFW_KEY_W},       {"A", GLFW_KEY_A},         {"S", GLFW_KEY_S},         {"D", GLFW_KEY_D},
      {"R", GLFW_KEY_R},       {"F", GLFW_KEY_F},         {"H", GLFW_KEY_H},         {"V", GLFW_KEY_V},
      {"1", GLFW_KEY_1},       {"2", GLFW_KEY_2},         {"3", GLFW_KEY_3},         {"4", GLFW_KEY_4},
      {"LEFT", GLFW_KEY_LEFT}, {"RIGHT", GLFW_KEY_RIGHT}, {"UP", GLFW_KEY_UP},       {"DOWN", GLFW_KEY_DOWN},
      {"HOME", GLFW_KEY_HOME}, {"TAB", GLFW_KEY_TAB},     {"F12", GLFW_KEY_F12},     {"ESCAPE", GLFW_KEY_ESCAPE},
      {"T", GLFW_KEY_T},       {"E", GLFW_KEY_E},         {"J", GLFW_KEY_J},         {"L", GLFW_KEY_L},
      {"I", GLFW_KEY_I},       {"K", GLFW_KEY_K},         {"SPACE", GLFW_KEY_SPACE}, {"O", GLFW_KEY_O},
  };
  return table;
}

std::string shown(const json& j) {
  std::string s = j.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}
  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    throw Error(name_ + ": " + path + ": " + message);
  }
  [[noreturn]] void expected(const std::string& path, const std::string& what, const json& got) const {
    fail(path, "expected " + what + ", got " + shown(got));
  }
  void keys(const json& obj, const std::string& path, const std::vector<std::string>& allowed) const {
    for (const auto& [k, v] : obj.items()) {
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      const std::string hint = nearest(k, allowed);
      fail(path.empty() ? k : path + "." + k,
           "unknown key" + (hint.empty() ? std::string() : "; did you mean \"" + hint + "\"?"));
    }
  }
  const json& need(const json& obj, const std::string& path, const std::string& key) const {
    if (!obj.contains(key)) fail(path, "missing \"" + key + "\"");
    return obj.at(key);
  }
  double number(const json& v, const std::string& path) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) expected(path, "a number", v);
    return v.get<double>();
  }
  int count(const json& v, const std::string& path, int min_value, const std::string& what) const {
    if (!v.is_number_integer() || v.get<long long>() < min_value || v.get<long long>() > (1 << 30))
      expected(path, what, v);
    return int(v.get<long long>());
  }
  std::string text(const json& v, const std::string& path, const std::string& what) const {
    if (!v.is_string() || v.get<std::string>().empty()) expected(path, what, v);
    return v.get<std::string>();
  }

 private:
  std::string name_;
};

ScriptEvent readEvent(const Reader& r, const json& e, const std::string& path) {
  if (!e.is_object()) r.expected(path, "an object {\"at_frame\": N, \"do\": ...}", e);
  ScriptEvent ev;
  ev.where = path;
  ev.at_frame = r.count(r.need(e, path, "at_frame"), path + ".at_frame", 0, "a frame number >= 0");
  const json& d = r.need(e, path, "do");
  std::string names;
  for (const auto& [k, v] : kinds()) names += (names.empty() ? "" : ", ") + k;
  if (!d.is_string()) r.expected(path + ".do", "one of " + names, d);
  const std::string what = d.get<std::string>();
  const auto it = kinds().find(what);
  if (it == kinds().end()) {
    std::vector<std::string> all;
    for (const auto& [k, v] : kinds()) all.push_back(k);
    const std::string hint = nearest(what, all);
    r.fail(path + ".do", "expected one of " + names + ", got \"" + what + "\"" +
                             (hint.empty() ? std::string() : "; did you mean \"" + hint + "\"?"));
  }
  ev.kind = it->second.first;
  std::vector<std::string> allowed = it->second.second;
  allowed.insert(allowed.end(), {"at_frame", "do"});
  r.keys(e, path, allowed);
  switch (ev.kind) {
    case EventKind::Set:
      ev.path = r.text(r.need(e, path, "path"), path + ".path", "a scene path as --set takes it (\"render.mode\")");
      ev.value_json = r.need(e, path, "value").dump();
      break;
    case EventKind::TurnElement:
      ev.element = r.text(r.need(e, path, "element"), path + ".element", "an element's name");
      [[fallthrough]];
    case EventKind::TurnHead:
      if (!e.contains("yaw_deg") && !e.contains("pitch_deg")) r.fail(path, "missing \"yaw_deg\" or \"pitch_deg\"");
      if (e.contains("yaw_deg")) ev.yaw_deg = r.number(e.at("yaw_deg"), path + ".yaw_deg");
      if (e.contains("pitch_deg")) ev.pitch_deg = r.number(e.at("pitch_deg"), path + ".pitch_deg");
      break;
    case EventKind::MoveElement:
      ev.element = r.text(r.need(e, path, "element"), path + ".element", "an element's name");
      [[fallthrough]];
    case EventKind::MoveEye: {
      const json& by = r.need(e, path, "by");
      if (!by.is_array() || by.size() != 3) r.expected(path + ".by", "[x, y, z] in metres", by);
      for (int k = 0; k < 3; ++k) ev.by_m[k] = r.number(by[size_t(k)], path + ".by[" + std::to_string(k) + "]");
      break;
    }
    case EventKind::Screenshot:
      ev.file = r.text(r.need(e, path, "file"), path + ".file", "a PNG file name");
      if (ev.file.size() < 4 || ev.file.substr(ev.file.size() - 4) != ".png")
        r.expected(path + ".file", "a file name ending in \".png\"", e.at("file"));
      if (e.contains("panel")) {
        const json& p = e.at("panel");
        if (p.is_string() && p.get<std::string>() == "shown")
          ev.shown = true;
        else if (p.is_boolean())
          ev.with_panel = p.get<bool>();
        else
          r.expected(path + ".panel", "true, false or \"shown\"", p);
      }
      break;
    case EventKind::SaveView:
      ev.file = r.text(r.need(e, path, "file"), path + ".file", "a scene file name");
      if (ev.file.size() < 5 || ev.file.substr(ev.file.size() - 5) != ".json")
        r.expected(path + ".file", "a file name ending in \".json\"", e.at("file"));
      break;
    case EventKind::Key: {
      const std::string name = r.text(r.need(e, path, "key"), path + ".key", "a GLFW key name");
      const auto k = keyCodes().find(name);
      if (k == keyCodes().end()) {
        std::string names;
        std::vector<std::string> all;
        for (const auto& [n, code] : keyCodes()) names += (names.empty() ? "" : ", ") + n, all.push_back(n);
        const std::string hint = nearest(name, all);
        r.fail(path + ".key", "expected one of " + names + ", got \"" + name + "\"" +
                                  (hint.empty() ? std::string() : "; did you mean \"" + hint + "\"?"));
      }
      ev.key = k->second;
      if (e.contains("shift")) {
        if (!e.at("shift").is_boolean()) r.expected(path + ".shift", "true or false", e.at("shift"));
        ev.shift = e.at("shift").get<bool>();
      }
      break;
    }
    case EventKind::Reference:
    case EventKind::Quit: break;
    case EventKind::Wipe:
      ev.wipe_x = r.number(r.need(e, path, "x"), path + ".x");
      if (ev.wipe_x < 0 || ev.wipe_x > 1)
        r.expected(path + ".x", "a number from 0 (all reference) to 1 (all mode)", e.at("x"));
      break;
    case EventKind::Overlay:
      if (!r.need(e, path, "on").is_boolean()) r.expected(path + ".on", "true or false", e.at("on"));
      ev.on = e.at("on").get<bool>();
      break;
    case EventKind::Drag: {
      if (e.contains("button") && e.at("button") != "left") r.expected(path + ".button", "\"left\"", e.at("button"));
      const auto point = [&](const char* key, Vec2* out) {
        const json& v = r.need(e, path, key);
        if (!v.is_array() || v.size() != 2) r.expected(path + "." + key, "[x, y] in window pixels", v);
        for (int k = 0; k < 2; ++k)
          (*out)[k] = r.number(v[size_t(k)], path + "." + key + "[" + std::to_string(k) + "]");
      };
      point("from", &ev.from_px);
      point("to", &ev.to_px);
      break;
    }
    case EventKind::Time:
      ev.time_s = r.number(r.need(e, path, "t"), path + ".t");
      if (!(ev.time_s >= 0) || ev.time_s > 1e6) r.expected(path + ".t", "a time in seconds from 0 to 1e6", e.at("t"));
      if (e.contains("play")) {
        if (!e.at("play").is_boolean()) r.expected(path + ".play", "true or false", e.at("play"));
        ev.on = e.at("play").get<bool>();
      }
      break;
    case EventKind::Cursor: {
      const json& v = r.need(e, path, "at");
      if (!v.is_array() || v.size() != 2) r.expected(path + ".at", "[x, y] in window pixels", v);
      for (int k = 0; k < 2; ++k) ev.at_px[k] = r.number(v[size_t(k)], path + ".at[" + std::to_string(k) + "]");
      break;
    }
  }
  return ev;
}

// 1-based line and column of byte `offset` (nlohmann's parse_error::byte: characters read so far).
std::string lineColumn(const std::string& text, size_t offset) {
  const size_t last = std::min(offset == 0 ? 0 : offset - 1, text.size());
  size_t line = 1, start = 0;
  for (size_t i = 0; i < last; ++i)
    if (text[i] == '\n') line++, start = i + 1;
  return std::to_string(line) + ":" + std::to_string(last - start + 1);
}

}  // namespace

Script parseScript(const std::string& json_text, const std::string& name) {
  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::parse_error& e) {
    std::string reason = e.what();
    const size_t col = reason.find("column ");
    const size_t colon = col == std::string::npos ? std::string::npos : reason.find(": ", col);
    if (colon != std::string::npos) reason = reason.substr(colon + 2);
    throw Error(name + ":" + lineColumn(json_text, e.byte) + ": syntax error: " + reason);
  }
  const Reader r(name);
  if (!doc.is_object()) r.expected("(top level)", "an object {\"size\": [w, h], \"events\": [...]}", doc);
  r.keys(doc, "", {"size", "events"});
  Script s;
  if (doc.contains("size")) {
    const json& sz = doc.at("size");
    if (!sz.is_array() || sz.size() != 2) r.expected("size", "[width, height] in pixels", sz);
    s.width = r.count(sz[0], "size[0]", 16, "a width of at least 16 pixels");
    s.height = r.count(sz[1], "size[1]", 16, "a height of at least 16 pixels");
    if (s.width > 16384 || s.height > 16384) r.expected("size", "at most 16384 x 16384 pixels", sz);
  }
  const json& events = r.need(doc, "(top level)", "events");
  if (!events.is_array()) r.expected("events", "an array of events", events);
  for (size_t i = 0; i < events.size(); ++i)
    s.events.push_back(readEvent(r, events[i], "events[" + std::to_string(i) + "]"));
  std::stable_sort(s.events.begin(), s.events.end(),
                   [](const ScriptEvent& a, const ScriptEvent& b) { return a.at_frame < b.at_frame; });
  return s;
}

Script loadScript(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read the script file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseScript(ss.str(), path);
}

}  // namespace pvrr::app::view

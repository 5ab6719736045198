#include "app/view/save_view.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr::app::view {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The node at a --set path ("elements[0].tessellation"), made where missing. The path was validated when the
// override was first applied to the scene (pvrr/scene/scene_json.h), so only its shape is read here.
json& nodeAt(json& doc, const std::string& path) {
  json* node = &doc;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '.') {
      ++i;
      continue;
    }
    if (path[i] == '[') {
      const size_t close = path.find(']', i);
      if (close == std::string::npos) throw Error("save view: malformed path \"" + path + "\"");
      node = &(*node)[size_t(std::stoul(path.substr(i + 1, close - i - 1)))];
      i = close + 1;
      continue;
    }
    const size_t end = path.find_first_of(".[", i);
    const std::string key = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
    node = &(*node)[key];
    i = end == std::string::npos ? path.size() : end;
  }
  return *node;
}

void rebaseFileNames(json& j, const fs::path& from_dir, const fs::path& to_dir) {
  if (j.is_array()) {
    for (json& v : j) rebaseFileNames(v, from_dir, to_dir);
  } else if (j.is_object()) {
    for (auto& [k, v] : j.items()) {
      if ((k == "file" || k == "image") && v.is_string() && fs::path(v.get<std::string>()).is_relative()) {
        const fs::path abs = fs::absolute(from_dir / v.get<std::string>()).lexically_normal();
        v = abs.lexically_relative(to_dir).generic_string();
      } else {
        rebaseFileNames(v, from_dir, to_dir);
      }
    }
  }
}

json vec(const Vec3& v, double unit_m) { return json::array({v.x / unit_m, v.y / unit_m, v.z / unit_m}); }

}  // namespace

void saveView(const std::string& out_path, const std::string& scene_path, const std::vector<std::string>& overrides,
              const Observer& ob, double unit_m) {
  std::ifstream in(scene_path, std::ios::binary);
  if (!in) throw Error(scene_path + ": cannot read the scene file to save the view");
  std::stringstream ss;
  ss << in.rdbuf();
  json doc = json::parse(ss.str());  // it loaded before, so it parses
  for (const std::string& o : overrides) {
    const size_t eq = o.find('=');
    const std::string value = o.substr(eq + 1);
    json v = json::parse(value, nullptr, false);
    nodeAt(doc, o.substr(0, eq)) = v.is_discarded() ? json(value) : v;  // as --set reads a value
  }
  json& o = doc["observer"];
  o["eye"] = vec(ob.eye, unit_m);
  o["target"] = vec(ob.target, unit_m);
  o["up"] = json::array({ob.up.x, ob.up.y, ob.up.z});
  o["image_size"] = json::array({ob.width, ob.height});
  const fs::path out_dir = fs::absolute(fs::path(out_path)).parent_path().lexically_normal();
  rebaseFileNames(doc, fs::absolute(fs::path(scene_path)).parent_path(), out_dir);
  writeFileAtomic(out_path, doc.dump(2) + "\n");
}

}  // namespace pvrr::app::view

#include "pvrr/scene/scene_json.h"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "pvrr/base/error.h"
#include "pvrr/base/names.h"
#include "pvrr/scene/scene_json_read.h"

namespace pvrr {
namespace {

using namespace scene_json_detail;

std::pair<size_t, size_t> lineColumn(const std::string& text, size_t position) {
  // position: characters read so far, i.e. the 1-based index of the last character read.
  const size_t last = std::min(position == 0 ? 0 : position - 1, text.size());
  size_t line = 1, line_start = 0;
  for (size_t i = 0; i < last; ++i)
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  return {line, last - line_start + 1};
}

class SyntaxCheck : public nlohmann::json_sax<json> {
 public:
  SyntaxCheck(const std::string& text, const std::string& file) : text_(text), file_(file) {}
  std::string error;

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    frames_.push_back(Frame{false, {}, 0, {}});
    return true;
  }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    f.key = k;
    if (!f.keys.insert(k).second) {
      error = file_ + ": " + path() + ": expected each key once in an object, got " + inQuotes(k) + " twice";
      return false;
    }
    return true;
  }
  bool end_object() override {
    frames_.pop_back();
    return value();
  }
  bool start_array(std::size_t) override {
    frames_.push_back(Frame{true, {}, 0, {}});
    return true;
  }
  bool end_array() override {
    frames_.pop_back();
    return value();
  }
  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) override {
    const auto [line, col] = lineColumn(text_, position);
    const std::string where = file_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
    if (ex.id == 406) {  // out_of_range.406: a number literal beyond double range (e.g. 1e999)
      error = where + path() + ": expected a finite number, got " + last_token;
      return false;
    }
    std::string reason = ex.what();
    const size_t col_pos = reason.find("column ");
    const size_t colon = col_pos == std::string::npos ? std::string::npos : reason.find(": ", col_pos);
    if (colon != std::string::npos) reason = reason.substr(colon + 2);
    error = where + reason;
    return false;
  }

 private:
  struct Frame {
    bool array;
    std::string key;
    size_t index;
    std::set<std::string> keys;
  };
  bool value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) p = f.array ? indexPath(p, f.index) : childPath(p, f.key);
    return p.empty() ? "(top level)" : p;
  }
  const std::string& text_;
  const std::string& file_;
  std::vector<Frame> frames_;
};

json parseJson(const std::string& text, const std::string& file) {
  SyntaxCheck check(text, file);
  if (!json::sax_parse(text, &check) || !check.error.empty())
    throw Error(check.error.empty() ? file + ": not a JSON document" : check.error);
  return json::parse(text);
}

// ---------------------------------------------------------------------------------------------------------
// --set overrides

struct Segment {
  bool is_index = false;
  std::string key;
  size_t index = 0;
};

Override applyOverride(json& doc, const std::string& text, const std::string& file) {
  const std::string prefix = file + ": --set " + text + ": ";
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(prefix + "expected PATH=VALUE (e.g. render.map_size=512), got " + inQuotes(text));
  const std::string path_text = text.substr(0, eq), value_text = text.substr(eq + 1);
  std::vector<Segment> segs;
  const auto bad_path = [&]() -> Error {
    return Error(prefix + "expected a path like elements[0].pose.position, got " + inQuotes(path_text));
  };
  size_t i = 0;
  while (i < path_text.size()) {
    if (path_text[i] == '[') {
      const size_t close = path_text.find(']', i);
      if (close == std::string::npos || close == i + 1) throw bad_path();
      const std::string digits = path_text.substr(i + 1, close - i - 1);
      if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) throw bad_path();
      segs.push_back(Segment{true, {}, static_cast<size_t>(std::stoul(digits))});
      i = close + 1;
      if (i < path_text.size() && path_text[i] == '.') {
        ++i;
        if (i == path_text.size()) throw bad_path();
      }
    } else {
      const size_t end = path_text.find_first_of(".[", i);
      const std::string key = path_text.substr(i, end == std::string::npos ? std::string::npos : end - i);
      if (key.empty()) throw bad_path();
      segs.push_back(Segment{false, key, 0});
      i = end == std::string::npos ? path_text.size() : end;
      if (i < path_text.size() && path_text[i] == '.') {
        ++i;
        if (i == path_text.size()) throw bad_path();
      }
    }
  }
  if (segs.empty() || segs.front().is_index) throw bad_path();

  json value;
  try {
    value = json::parse(value_text);
  } catch (const json::exception&) {
    value = value_text;  // not JSON: a string (render.mode=raster)
  }

  json* cur = &doc;
  std::string so_far;
  for (const Segment& s : segs) {
    if (s.is_index) {
      if (!cur->is_array())
        throw Error(prefix + so_far + ": expected an array to index, got " + show(cur->is_null() ? nullptr : cur));
      if (s.index >= cur->size())
        throw Error(prefix + indexPath(so_far, s.index) + ": expected an index < " + std::to_string(cur->size()) +
                    " (" + so_far + " has " + std::to_string(cur->size()) + " entries), got " + std::to_string(s.index));
      so_far = indexPath(so_far, s.index);
      cur = &(*cur)[s.index];
    } else {
      if (cur->is_null()) *cur = json::object();  // a section the file leaves out (e.g. "render")
      if (!cur->is_object())
        throw Error(prefix + (so_far.empty() ? "(top level)" : so_far) + ": expected an object to hold " +
                    inQuotes(s.key) + ", got " + show(cur));
      so_far = childPath(so_far, s.key);
      cur = &(*cur)[s.key];
    }
  }
  *cur = value;
  return Override{so_far, text};
}

}  // namespace

// -----------------------------------------------------------------------------------------------------------

int editDistance(const std::string& a, const std::string& b) {
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1));
  for (size_t i = 0; i <= n; ++i) d[i][0] = static_cast<int>(i);
  for (size_t j = 0; j <= m; ++j) d[0][j] = static_cast<int>(j);
  for (size_t i = 1; i <= n; ++i) {
    for (size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[n][m];
}

// The byte offset of the first byte that is not part of a well-formed UTF-8 sequence (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), or npos when the whole text is UTF-8.
static size_t firstInvalidUtf8(const std::string& text) {
  const auto* b = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  size_t i = 0;
  while (i < n) {
    const unsigned char c = b[i];
    size_t len = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
    if (c < 0x80) len = 1;
    else if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c == 0xE0) len = 3, lo = 0xA0;
    else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) len = 3;
    else if (c == 0xED) len = 3, hi = 0x9F;
    else if (c == 0xF0) len = 4, lo = 0x90;
    else if (c >= 0xF1 && c <= 0xF3) len = 4;
    else if (c == 0xF4) len = 4, hi = 0x8F;
    else return i;
    if (len > 1) {
      if (i + 1 >= n || b[i + 1] < lo || b[i + 1] > hi) return i;
      for (size_t k = 2; k < len; ++k)
        if (i + k >= n || b[i + k] < 0x80 || b[i + k] > 0xBF) return i;
    }
    i += len;
  }
  return std::string::npos;
}

SceneDesc parseScene(const std::string& json_text, const std::string& name_for_messages, const std::string& base_dir,
                     const std::vector<std::string>& set_overrides) {
  // UTF-8 first: the JSON parser's own message would quote the bad byte, and a --set value that is not UTF-8
  // was kept as a string that the JSON library cannot print (found by tests/fuzz/scene_fuzz.cpp).
  if (const size_t bad = firstInvalidUtf8(json_text); bad != std::string::npos) {
    const size_t line = size_t(std::count(json_text.begin(), json_text.begin() + std::ptrdiff_t(bad), '\n')) + 1;
    throw Error(name_for_messages + ": byte " + std::to_string(bad) + " (line " + std::to_string(line) +
                "): not valid UTF-8; a scene file is UTF-8 text");
  }
  for (const std::string& o : set_overrides)
    if (const size_t bad = firstInvalidUtf8(o); bad != std::string::npos) {
      std::string shown = o;
      for (char& ch : shown)
        if (static_cast<unsigned char>(ch) >= 0x80 || static_cast<unsigned char>(ch) < 0x20) ch = '?';
      throw Error(name_for_messages + ": --set " + shown + ": byte " + std::to_string(bad) +
                  " is not valid UTF-8 (non-ASCII bytes shown as ?)");
    }
  Ctx c;
  c.file = name_for_messages;
  c.base_dir = base_dir;
  json doc = parseJson(json_text, name_for_messages);
  for (const std::string& o : set_overrides) c.overrides.push_back(applyOverride(doc, o, name_for_messages));
  return readScene(c, doc);
}

SceneDesc loadScene(const std::string& path, const std::vector<std::string>& set_overrides) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(path + ": is a directory, expected a scene file (.json)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the scene file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(path + ": cannot read the scene file");
  const std::string dir = fs::path(path).parent_path().string();
  return parseScene(ss.str(), path, dir, set_overrides);  // checks UTF-8 first
}

}  // namespace pvrr

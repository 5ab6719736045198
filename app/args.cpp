#include "app/args.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pvrr/base/error.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::app {

void usageError(const std::string& command, const std::string& message) {
  throw Error("pvrr " + command + ": " + message + " (see: pvrr help " + command + ")");
}

std::string nearest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_d = std::string::npos;
  for (const std::string& c : candidates) {
    const size_t d = size_t(pvrr::editDistance(word, c));
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  // Only suggest what is plausibly a typo.
  return best_d <= std::max<size_t>(2, word.size() / 3) ? best : std::string();
}

Args::Args(const std::string& command, const std::vector<std::string>& argv, const std::set<std::string>& options,
           const std::set<std::string>& switches, const std::set<std::string>& repeatable)
    : command_(command) {
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.size() < 2 || a[0] != '-' || a[1] != '-') {
      positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2), value;
    bool has_value = false;
    if (size_t eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    if (switches.count(name)) {
      if (has_value) usageError(command, "--" + name + " takes no value");
      values_[name].push_back("1");
      continue;
    }
    if (!options.count(name)) {
      std::vector<std::string> all(options.begin(), options.end());
      all.insert(all.end(), switches.begin(), switches.end());
      std::string hint = nearest(name, all);
      usageError(command, "unknown option --" + name + (hint.empty() ? "" : "; did you mean --" + hint + "?"));
    }
    if (!has_value) {
      if (i + 1 >= argv.size()) usageError(command, "--" + name + " needs a value");
      value = argv[++i];
    }
    if (values_.count(name) && !repeatable.count(name)) usageError(command, "--" + name + " given twice");
    values_[name].push_back(value);
  }
}

bool Args::has(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second.back();
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto v = get(name);
  return v ? *v : fallback;
}

std::vector<std::string> Args::all(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

namespace {
bool parseDouble(const std::string& s, double& out) {
  std::istringstream is(s);
  is >> out;
  return !is.fail() && is.eof() && std::isfinite(out);
}
}  // namespace

int Args::getInt(const std::string& name, int fallback, int min_value) const {
  auto v = get(name);
  if (!v) return fallback;
  double d;
  if (!parseDouble(*v, d) || d != std::floor(d) || d < min_value || d > 1e9)
    usageError(command_, "--" + name + ": expected an integer >= " + std::to_string(min_value) + ", got \"" + *v + "\"");
  return int(d);
}

double Args::getDouble(const std::string& name, double fallback) const {
  auto v = get(name);
  if (!v) return fallback;
  double d;
  if (!parseDouble(*v, d)) usageError(command_, "--" + name + ": expected a finite number, got \"" + *v + "\"");
  return d;
}

std::optional<std::pair<int, int>> Args::getSize(const std::string& name) const {
  auto v = get(name);
  if (!v) return std::nullopt;
  size_t x = v->find('x');
  double w = 0, h = 0;
  if (x == std::string::npos || !parseDouble(v->substr(0, x), w) || !parseDouble(v->substr(x + 1), h) || w < 1 ||
      h < 1 || w > 16384 || h > 16384 || w != std::floor(w) || h != std::floor(h))
    usageError(command_, "--" + name + ": expected WIDTHxHEIGHT with integers 1..16384, got \"" + *v + "\"");
  return std::make_pair(int(w), int(h));
}

std::vector<double> Args::getNumbers(const std::string& name, size_t expected_count) const {
  auto v = get(name);
  if (!v) return {};
  std::vector<double> out;
  std::stringstream ss(*v);
  std::string item;
  while (std::getline(ss, item, ',')) {
    double d;
    if (!parseDouble(item, d)) usageError(command_, "--" + name + ": \"" + item + "\" is not a finite number");
    out.push_back(d);
  }
  if (expected_count && out.size() != expected_count)
    usageError(command_, "--" + name + ": expected " + std::to_string(expected_count) + " comma-separated numbers, got \"" + *v + "\"");
  return out;
}

}  // namespace pvrr::app

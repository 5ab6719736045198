// Command-line parsing for the pvrr subcommands: positional arguments, --flag VALUE / --flag=VALUE options
// (some repeatable), and boolean switches. Unknown options are usage errors that suggest the nearest one.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pvrr::app {

class Args {
 public:
  // `options` take a value; `repeatable` is the subset that may repeat; `switches` take none.
  Args(const std::string& command, const std::vector<std::string>& argv, const std::set<std::string>& options,
       const std::set<std::string>& switches = {}, const std::set<std::string>& repeatable = {});

  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& name) const;
  std::optional<std::string> get(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback) const;
  std::vector<std::string> all(const std::string& name) const;
  int getInt(const std::string& name, int fallback, int min_value) const;
  double getDouble(const std::string& name, double fallback) const;
  // "WxH" -> (w, h), both > 0.
  std::optional<std::pair<int, int>> getSize(const std::string& name) const;
  // "a,b,c" -> numbers.
  std::vector<double> getNumbers(const std::string& name, size_t expected_count) const;

 private:
  std::string command_;
  std::vector<std::string> positional_;
  std::map<std::string, std::vector<std::string>> values_;
};

// Throws pvrr::Error for a usage mistake: "pvrr <command>: <message>".
[[noreturn]] void usageError(const std::string& command, const std::string& message);
// The candidate nearest to `word` by edit distance, or "" when none is a plausible typo.
std::string nearest(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace pvrr::app

// Runs the built pvrr command from the source tree, as a user does, for the tests of tests/app.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>

namespace pvrr::test {

struct CliResult {
  int code = -1;
  std::string out, err;
};

// Runs a shell command, capturing its exit code (-1 when it did not exit normally) and both streams.
inline CliResult runCaptured(const std::string& command) {
  namespace fs = std::filesystem;
  static int counter = 0;
  const fs::path tmp = fs::temp_directory_path() / ("pvrr-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const std::string cmd = command + " >'" + tmp.string() + ".out' 2>'" + tmp.string() + ".err'";
  CliResult r;
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  r.out = slurp(tmp.string() + ".out");
  r.err = slurp(tmp.string() + ".err");
  fs::remove(tmp.string() + ".out");
  fs::remove(tmp.string() + ".err");
  return r;
}

// Runs build/pvrr with the arguments (a shell fragment) from the source tree, capturing both streams.
inline CliResult runPvrr(const std::string& args) {
  return runCaptured("cd '" PVRR_SOURCE_DIR "' && '" PVRR_BINARY "' " + args);
}

// The whole content of a file (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A refusal as the CLI's contract has it: exit code 1 and exactly one line on stderr, which contains `what`
// (the file and the place in it).
inline void expectOneLineError(const CliResult& r, const std::string& what) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

// The same with several pieces of the line, and none of `outputs` written (all or nothing).
inline void expectOneLineError(const CliResult& r, std::initializer_list<std::string> parts,
                               std::initializer_list<std::string> outputs = {}) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "expected one line, got:\n" << r.err;
  for (const std::string& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << "no \"" << p << "\" in: " << r.err;
  for (const std::string& o : outputs) EXPECT_FALSE(std::filesystem::exists(o)) << o;
}

// A fresh temporary folder per test, removed afterwards.
inline std::filesystem::path freshTestDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("pvrr-app-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace pvrr::test

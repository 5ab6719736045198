#include "pvrr/base/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "pvrr/base/error.h"

namespace pvrr {

namespace fs = std::filesystem;

namespace {

// The open transaction of this thread (OutputTransaction).
struct Staged {
  int depth = 0;                                             // open OutputTransaction objects
  std::vector<std::pair<std::string, std::string>> files;  // (temporary, target), in the order written
  std::vector<fs::path> folders;                            // folders made for them, outermost first
};
thread_local Staged staged;

void removeStaged() {
  std::error_code ec;
  for (const auto& f : staged.files) fs::remove(f.first, ec);
  for (auto it = staged.folders.rbegin(); it != staged.folders.rend(); ++it) fs::remove(*it, ec);  // if empty
  staged.files.clear();
  staged.folders.clear();
}

// Makes `folder` and its missing parents; in a transaction, records the ones it made.
void makeFolder(const fs::path& folder, std::error_code& ec) {
  std::vector<fs::path> missing;
  for (fs::path p = folder; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(folder, ec);
  if (!ec && staged.depth > 0) staged.folders.insert(staged.folders.end(), missing.rbegin(), missing.rend());
}

}  // namespace

std::string temporaryPathBeside(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  const std::string name = "." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(++counter) + target.extension().string();
  return (target.parent_path() / name).string();
}

void writeAtomic(const std::string& path, const std::function<void(const std::string&)>& write, MissingFolder folder) {
  const fs::path target(path);
  std::error_code ec;
  if (folder == MissingFolder::Create && target.has_parent_path()) {
    makeFolder(target.parent_path(), ec);
    if (ec) throw Error(path + ": cannot create the folder " + target.parent_path().string() + ": " + ec.message());
  }
  const std::string temporary = temporaryPathBeside(path);
  try {
    write(temporary);
  } catch (...) {
    fs::remove(temporary, ec);
    throw;
  }
  if (!fs::exists(temporary, ec)) throw Error(path + ": the file was not written");
  if (staged.depth > 0) {  // kept until the transaction commits
    for (auto& f : staged.files)
      if (f.second == path) {
        fs::remove(f.first, ec);
        f.first = temporary;
        return;
      }
    staged.files.emplace_back(temporary, path);
    return;
  }
  fs::rename(temporary, target, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temporary, ec);
    throw Error(path + ": cannot rename the temporary file into place: " + reason);
  }
}

OutputTransaction::OutputTransaction() : outermost_(staged.depth == 0) { ++staged.depth; }

OutputTransaction::~OutputTransaction() {
  --staged.depth;
  if (outermost_) removeStaged();  // nothing left after a commit
}

void OutputTransaction::commit() {
  if (!outermost_) return;
  std::error_code ec;
  for (const auto& file : staged.files)
    if (fs::is_directory(file.second, ec)) {
      const std::string target = file.second;
      removeStaged();
      throw Error(target + ": cannot write the file: a folder of that name is in the way");
    }
  for (size_t i = 0; i < staged.files.size(); ++i) {
    const std::string target = staged.files[i].second;
    fs::rename(staged.files[i].first, target, ec);
    if (ec) {
      const std::string reason = ec.message();
      staged.files.erase(staged.files.begin(), staged.files.begin() + long(i));  // renamed: they stay
      staged.folders.clear();  // they hold the outputs renamed so far
      removeStaged();
      throw Error(target + ": cannot rename the temporary file into place: " + reason);
    }
  }
  staged.files.clear();
  staged.folders.clear();
}

void writeFileAtomic(const std::string& path, const std::string& bytes, MissingFolder folder) {
  writeAtomic(
      path,
      [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(path + ": cannot write (could not open " + temporary + ")");
        out.write(bytes.data(), std::streamsize(bytes.size()));
        out.flush();
        if (!out) throw Error(path + ": write failed");
      },
      folder);
}

}  // namespace pvrr

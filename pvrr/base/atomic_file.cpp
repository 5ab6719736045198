#include "pvrr/base/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>

#include "pvrr/base/error.h"

namespace pvrr {

namespace fs = std::filesystem;

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
    fs::create_directories(target.parent_path(), ec);
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
  fs::rename(temporary, target, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temporary, ec);
    throw Error(path + ": cannot rename the temporary file into place: " + reason);
  }
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

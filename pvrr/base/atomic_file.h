// Output files are written whole or not at all: each is written to a temporary file beside its target (same
// folder, same extension, so that writers that decide details by the extension still do) and renamed onto the
// target only when the writer succeeded. On any failure the temporary file is removed, pvrr::Error (naming the
// target and the reason) is thrown, and the target is left as it was. Atomic against readers and failures, not
// against power loss (nothing is fsync'ed). Every output of pvrr goes through here.
#pragma once
#include <functional>
#include <string>

namespace pvrr {

// What to do when the target's folder does not exist.
enum class MissingFolder { Create, Fail };

// A temporary path beside `path`: "<folder>/.<stem>.tmp-<pid>-<n><extension>", unique in this process.
std::string temporaryPathBeside(const std::string& path);

// Writes `path` by calling write(temporary) and renaming the temporary onto `path`. `write` throws pvrr::Error on
// failure; a writer that returns without creating the temporary is a failure too.
void writeAtomic(const std::string& path, const std::function<void(const std::string& temporary)>& write,
                 MissingFolder folder = MissingFolder::Create);

// `bytes` as the whole content of `path` (binary, unchanged).
void writeFileAtomic(const std::string& path, const std::string& bytes, MissingFolder folder = MissingFolder::Create);

}  // namespace pvrr

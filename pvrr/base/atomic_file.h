// Output files are written whole or not at all: each is written to a temporary file beside its target (same
// folder, same extension, so that writers that decide details by the extension still do) and renamed onto the
// target only when the writer succeeded. On any failure the temporary file is removed, pvrr::Error (naming the
// target and the reason) is thrown, and the target is left as it was. Atomic against readers and failures, not
// against power loss (nothing is fsync'ed). Every output of pvrr goes through here.
//
// A command with several outputs opens an OutputTransaction: its outputs then appear together when it commits,
// and none of them (nor a folder made for them) when it fails at any point.
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

// A command's outputs as one. While one is open on this thread, writeAtomic keeps each finished temporary beside
// its target instead of renaming it (writing the same target again replaces the kept one); commit() renames them
// all onto their targets; a transaction that ends without commit() removes them, and the folders writeAtomic
// made for them where they are left empty. The files that were there before stay as they were. A transaction
// opened while another is open on the same thread joins it: only the outermost one commits or rolls back.
// commit() first checks that every target can be replaced (not a folder), so that a failure there leaves
// nothing renamed; a rename that fails after that (a disk error) leaves the ones before it in place.
class OutputTransaction {
 public:
  OutputTransaction();
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  void commit();

 private:
  bool outermost_;
};

}  // namespace pvrr

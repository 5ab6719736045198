// pvrr/base/atomic_file.h: a file is written whole or not at all, and no temporary file is left behind.
#include "pvrr/base/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "pvrr/base/error.h"
#include "support/temp_dir.h"

namespace pvrr {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(AtomicFile, WritesTheBytesAndLeavesNoTemporary) {
  TempDir dir;
  const std::string path = (dir.path() / "out.json").string();
  const std::string bytes("{\"a\": 1}\n\0binary", 16);
  writeFileAtomic(path, bytes);
  EXPECT_EQ(slurp(path), bytes);
  writeFileAtomic(path, "second");  // replaces the file whole
  EXPECT_EQ(slurp(path), "second");
  EXPECT_EQ(dir.entries(), 1u);
}

TEST(AtomicFile, TemporaryLiesBesideTheTargetWithItsExtension) {
  // Writers that decide by the extension (VTK, OCCT) must see the target's.
  const fs::path t(temporaryPathBeside("/some/folder/mesh.vtp"));
  EXPECT_EQ(t.parent_path(), fs::path("/some/folder"));
  EXPECT_EQ(t.extension(), ".vtp");
  EXPECT_NE(t.filename(), "mesh.vtp");
  EXPECT_NE(temporaryPathBeside("/x/a.png"), temporaryPathBeside("/x/a.png"));  // unique per call
}

TEST(AtomicFile, FailingWriterLeavesTheTargetAsItWas) {
  TempDir dir;
  const fs::path path = dir.path() / "keep.txt";
  std::ofstream(path) << "old";
  EXPECT_THROW(writeAtomic(path.string(),
                           [](const std::string& temp) {
                             std::ofstream(temp) << "half";
                             throw Error("writer failed");
                           }),
               Error);
  EXPECT_EQ(slurp(path), "old");
  EXPECT_EQ(dir.entries(), 1u) << "temporary file left behind";
  // A writer that returns without creating its file fails too.
  try {
    writeAtomic(path.string(), [](const std::string&) {});
    FAIL() << "a writer that wrote nothing succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(path), "old");
}

TEST(AtomicFile, MissingFolderIsCreatedOrRefused) {
  TempDir dir;
  const fs::path nested = dir.path() / "a" / "b" / "out.txt";
  EXPECT_THROW(writeFileAtomic(nested.string(), "x", MissingFolder::Fail), Error);
  EXPECT_EQ(dir.entries(), 0u);
  writeFileAtomic(nested.string(), "x", MissingFolder::Create);
  EXPECT_EQ(slurp(nested), "x");
}

TEST(AtomicFile, FailedRenameNamesTheTargetAndRemovesTheTemporary) {
  TempDir dir;
  const fs::path target = dir.path() / "occupied";
  fs::create_directory(target);
  std::ofstream(target / "keep.txt") << "x";  // a non-empty folder: rename onto it fails
  try {
    writeFileAtomic(target.string(), "data");
    FAIL() << "rename onto a non-empty folder succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(dir.entries(), 1u) << "temporary file left behind";
  EXPECT_TRUE(fs::is_directory(target));
}

TEST(OutputTransaction, OutputsAppearTogetherOnCommit) {
  TempDir dir;
  const fs::path a = dir.path() / "a.txt", b = dir.path() / "sub" / "b.txt";
  {
    OutputTransaction outputs;
    writeFileAtomic(a.string(), "first");
    writeFileAtomic(a.string(), "A");  // written again: the later content wins, one temporary kept
    {
      OutputTransaction inner;  // joins the outer one
      writeFileAtomic(b.string(), "B");
      inner.commit();
    }
    EXPECT_FALSE(fs::exists(a)) << "an output appeared before the command committed";
    EXPECT_FALSE(fs::exists(b));
    outputs.commit();
  }
  EXPECT_EQ(slurp(a), "A");
  EXPECT_EQ(slurp(b), "B");
  EXPECT_EQ(dir.entries(), 2u);  // a.txt and sub/, no temporaries
}

TEST(OutputTransaction, FailureLeavesNoneAndTheOldFilesUnchanged) {
  TempDir dir;
  const fs::path old = dir.path() / "a.txt";
  std::ofstream(old) << "old";
  {
    OutputTransaction outputs;
    writeFileAtomic(old.string(), "new");
    writeFileAtomic((dir.path() / "made" / "deep" / "b.txt").string(), "B");
    // the command fails here: no commit
  }
  EXPECT_EQ(slurp(old), "old");
  EXPECT_EQ(dir.entries(), 1u) << "a temporary or a folder made for the outputs was left";
}

TEST(OutputTransaction, TargetInTheWayRenamesNothing) {
  TempDir dir;
  const fs::path a = dir.path() / "a.txt", blocked = dir.path() / "b.txt";
  fs::create_directory(blocked);
  std::ofstream(blocked / "keep") << "x";
  OutputTransaction outputs;
  writeFileAtomic(a.string(), "A");
  writeFileAtomic(blocked.string(), "B");
  try {
    outputs.commit();
    FAIL() << "commit onto a folder succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(blocked.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(a)) << "an earlier output appeared although a later one failed";
  EXPECT_EQ(dir.entries(), 1u);
}

}  // namespace
}  // namespace pvrr

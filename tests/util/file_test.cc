#include "nphand/util/file.h"

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::ExpectError;

TEST(FileTest, SecondLockOfAFileIsRefusedUntilTheFirstCloses) {
  const auto path = testing::ScratchDir() / "x.partial";
  File first = File::OpenLocked(path);
  ExpectError([&] { File::OpenLocked(path); }, "x.partial: another nphand process is writing it");
  first.Close();
  EXPECT_NO_THROW(File::OpenLocked(path));
}

TEST(FileTest, ReadsAndWritesAtOffsets) {
  const auto path = testing::ScratchDir() / "x.bin";
  File file = File::OpenLocked(path);
  const std::vector<uint8_t> bytes = {1, 2, 3, 4};
  file.WriteAt(0, bytes);
  file.Append(bytes);
  EXPECT_EQ(file.Size(), 8u);
  std::vector<uint8_t> read(3);
  EXPECT_TRUE(file.ReadAt(5, read));
  EXPECT_EQ(read, (std::vector<uint8_t>{2, 3, 4}));
  EXPECT_FALSE(file.ReadAt(6, read)) << "the file ends first";
  file.Truncate(2);
  EXPECT_EQ(ReadFileBytes(path), (std::vector<uint8_t>{1, 2}));
}

TEST(FileTest, OutputPathsAreCheckedBeforeAnyWork) {
  const auto dir = testing::ScratchDir();
  std::filesystem::create_directories(dir / "folder");
  WriteFileAtomic(dir / "file", std::string("x"));
  ExpectError([&] { CheckOutputFile("", "--out"); }, "--out: the output path is empty");
  ExpectError([&] { CheckOutputFile(dir / "folder", "--out"); }, "is a folder");
  ExpectError([&] { CheckOutputFile(dir / "folder" / "", "--out"); }, "names a folder");
  ExpectError([&] { CheckOutputFile(dir / "folder" / "..", "--out"); }, "names a folder");
  ExpectError([&] { CheckOutputFile(dir / "file" / "x.db", "--out"); }, "is a file, not a folder");
  EXPECT_NO_THROW(CheckOutputFile(dir / "new" / "x.db", "--out"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "new")) << "the folder is made";
  EXPECT_NO_THROW(CheckOutputFile(dir / "file", "--out")) << "an existing file is replaced";
  ExpectError([&] { CheckOutputFolder(dir / "file", "--out"); }, "is a file, not a folder");
  EXPECT_NO_THROW(CheckOutputFolder(dir / "made", "--out"));
  for (const char* name : {"../x", "a/b", "..", ".", ""}) {
    ExpectError([&] { CheckFileName(name, "--name"); }, "must be a file name");
  }
  EXPECT_NO_THROW(CheckFileName("feature_study", "--name"));
}

}  // namespace
}  // namespace nphand

#include "nphand/util/file.h"

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <fstream>

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

TEST(FileTest, AnOutputThatIsAnInputIsRefusedHoweverItIsNamed) {
  const auto dir = testing::ScratchDir();
  std::filesystem::create_directories(dir / "x");
  WriteFileAtomic(dir / "D", std::string("database"));
  std::filesystem::create_symlink(dir / "D", dir / "link");
  std::filesystem::create_hard_link(dir / "D", dir / "hard");
  const std::vector<NamedPath> inputs = {{dir / "D", "--db"}};
  for (const std::filesystem::path& out : {dir / "D", dir / "x" / ".." / "." / "D", dir / "link", dir / "hard"}) {
    ExpectError([&] { CheckOutputsApart(inputs, {{dir / "new", "--overlay"}, {out, "--out"}}); },
                "--out '" + out.string() + "' is --db '" + (dir / "D").string() + "': writing it would destroy an input");
  }
  ExpectError([&] { CheckOutputsApart({{dir / "link", "--db"}}, {{dir / "D", "--out"}}); }, "would destroy an input");
  ExpectError([&] { CheckOutputsApart({}, {{dir / "a.jsonl", "--out"}, {dir / "x" / ".." / "a.jsonl", "--overlay"}}); },
              "are the same file: one output would overwrite the other");
  EXPECT_NO_THROW(CheckOutputsApart(inputs, {{dir / "D.jsonl", "--out"}, {dir / "D.mp4", "--overlay"}}));
  // An output folder: its files of the written kinds, not others.
  WriteFileAtomic(dir / "x" / "truth.json", std::string("{}"));
  ExpectError([&] { CheckOutputsApart({{dir / "x" / "truth.json", "--truth"}}, {{dir / "x", "--out", {".json", ".png"}}}); },
              "lies in --out");
  EXPECT_NO_THROW(CheckOutputsApart({{dir / "x" / "truth.jsonl", "--truth"}}, {{dir / "x", "--out", {".json", ".png"}}}));
}

TEST(FileTest, ALineFileHoldsWholeLinesTakesItsNameOnCommitAndRefusesASecondWriter) {
  const auto dir = testing::ScratchDir();
  WriteFileAtomic(dir / "poses.jsonl", std::string("the old run\n"));
  {
    LineFile first(dir / "poses.jsonl");
    first.Write("{\"frame\":0}");
    ExpectError([&] { LineFile second(dir / "poses.jsonl"); }, "another nphand process is writing it");
    first.Write("{\"frame\":1}");
    EXPECT_EQ(first.lines(), 2u);
    EXPECT_EQ(ReadFileBytes(dir / "poses.jsonl").size(), 12u) << "the final name is untouched until the commit";
    first.Commit();
  }
  const std::vector<uint8_t> bytes = ReadFileBytes(dir / "poses.jsonl");
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "{\"frame\":0}\n{\"frame\":1}\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "poses.jsonl.partial"));
  {
    LineFile dropped(dir / "other.jsonl");
    dropped.Write("x");
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "other.jsonl.partial")) << "dropped uncommitted: removed";
  EXPECT_FALSE(std::filesystem::exists(dir / "other.jsonl"));
}

TEST(FileTest, ALineFileOnAFullDiskKeepsOnlyWholeLines) {
  // A file size limit makes writes fail as a full disk does; in a child, so that the limit
  // ends with it.
  const auto path = testing::ScratchDir() / "full.jsonl";
  const std::string line(100, 'x');
  EXPECT_EXIT(
      {
        std::signal(SIGXFSZ, SIG_IGN);
        rlimit limit;
        limit.rlim_cur = limit.rlim_max = 250;
        ::setrlimit(RLIMIT_FSIZE, &limit);
        LineFile file(path);
        file.Keep();
        try {
          for (int i = 0; i < 10; ++i) file.Write(line);
        } catch (const Error& e) {
          std::fprintf(stderr, "%s\n", e.what());
          std::_Exit(3);
        }
        std::_Exit(0);
      },
      ::testing::ExitedWithCode(3), "full.jsonl.partial: write failed");
  const std::vector<uint8_t> bytes = ReadFileBytes(path.string() + ".partial");
  EXPECT_EQ(bytes.size(), 202u) << "two whole lines; the third's first 48 bytes were cut off again";
}

}  // namespace
}  // namespace nphand

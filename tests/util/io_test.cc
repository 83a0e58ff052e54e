#include "nphand/util/io.h"

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

TEST(IoTest, AtomicWriteRoundTripsAndLeavesNoTemporary) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> bytes = {0, 1, 2, 250, 255};
  WriteFileAtomic(dir / "a.bin", bytes);
  EXPECT_EQ(ReadFileBytes(dir / "a.bin"), bytes);
  WriteFileAtomic(dir / "a.bin", std::string("replaced"));
  const std::vector<uint8_t> text = ReadFileBytes(dir / "a.bin");
  EXPECT_EQ(std::string(text.begin(), text.end()), "replaced");
  EXPECT_FALSE(std::filesystem::exists(dir / "a.bin.tmp"));
}

TEST(IoTest, MissingFileErrorNamesThePath) {
  const auto path = testing::ScratchDir() / "missing.bin";
  try {
    ReadFileBytes(path);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos);
  }
}

TEST(IoTest, OnlyRegularFilesAreReadAndAFifoIsNotWaitedOn) {
  const auto dir = testing::ScratchDir();
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  const auto expect_refused = [](const std::filesystem::path& path, const std::string& needle) {
    try {
      ReadFileBytes(path);
      ADD_FAILURE() << "read " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path.string() + ": is " + needle), std::string::npos) << e.what();
    }
  };
  expect_refused(dir / "fifo", "a FIFO");
  expect_refused(dir, "a folder");
  expect_refused("/dev/null", "a device");
}

TEST(IoTest, WriteIntoMissingFolderFails) {
  EXPECT_THROW(WriteFileAtomic(testing::ScratchDir() / "no" / "such" / "x", std::string("x")), Error);
}

TEST(IoTest, Sha256MatchesKnownDigests) {
  const std::string abc = "abc";
  EXPECT_EQ(Sha256Hex({reinterpret_cast<const uint8_t*>(abc.data()), abc.size()}),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex({}), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

}  // namespace
}  // namespace nphand

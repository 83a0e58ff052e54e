// The main of every test binary: runs the tests, then removes this process's scratch
// folders.
#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  std::error_code ignored;
  std::filesystem::remove_all(std::filesystem::temp_directory_path() / ("nphand_test_" + std::to_string(::getpid())),
                              ignored);
  return status;
}

// Files as nphand opens them: only regular files are read (a FIFO, a folder or a device is
// refused by name, never waited on), writers hold an exclusive lock, and output paths are
// checked before any work is done.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace nphand {

// An open file descriptor, closed on destruction. Every failure throws nphand::Error
// naming the path.
class File {
 public:
  // Opens an existing regular file for reading. Refuses a folder, FIFO, socket or device by
  // name without blocking (a FIFO is opened non-blocking, then refused).
  static File OpenRegular(const std::filesystem::path& path);
  // Opens (creating it if missing) a regular file for reading and writing and takes an
  // exclusive advisory lock on it (flock). Throws if another process or File holds the
  // lock, naming the file. The lock is on the file the path names when it is taken: if
  // the path is renamed away meanwhile, the newly named file is opened instead.
  static File OpenLocked(const std::filesystem::path& path);

  File() = default;
  ~File();
  File(File&& other) noexcept;
  File& operator=(File&& other) noexcept;
  File(const File&) = delete;
  File& operator=(const File&) = delete;

  int fd() const { return fd_; }
  const std::filesystem::path& path() const { return path_; }
  uint64_t Size() const;
  // Reads exactly bytes.size() bytes at `offset`; false if the file ends first.
  bool ReadAt(uint64_t offset, std::span<uint8_t> bytes) const;
  // Appends at the end of the file, or writes at `offset`.
  void Append(std::span<const uint8_t> bytes);
  void WriteAt(uint64_t offset, std::span<const uint8_t> bytes);
  void Truncate(uint64_t size);
  void Sync();
  void Close();

 private:
  File(int fd, std::filesystem::path path) : fd_(fd), path_(std::move(path)) {}
  int fd_ = -1;
  std::filesystem::path path_;
};

// Checks that a file can be written at `path` before any work is done: the path is not
// empty, names a file (not "dir/", ".", ".."), is not a folder or anything but a regular
// file, and its folder exists (it is created) and is writable. `what` names the option in
// the message ("--out").
void CheckOutputFile(const std::filesystem::path& path, const std::string& what);
// The same for an output folder: created if missing, refused if it is a file or not
// writable.
void CheckOutputFolder(const std::filesystem::path& path, const std::string& what);
// A path a command reads or writes, with the option that names it in messages ("--db").
// An output folder (`extensions` not empty) stands for the files of those extensions
// (".json", ".png") the command writes into it.
struct NamedPath {
  std::filesystem::path path;
  std::string what;
  std::vector<std::string> extensions = {};
};

// Refuses, before any work, an output that is an input or another output: paths are
// compared as the files they reach (symlinks, "..", "." and hard links resolved). An input
// inside an output folder with one of the extensions written there is refused too. Throws
// nphand::Error naming both options and the file.
void CheckOutputsApart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

// A text file written line by line under "<path>.partial", locked against other writers
// (a second writer is refused by name, and nothing of the first's is touched), holding only
// whole lines: a line whose write fails (a full disk) is cut off again before the error is
// thrown. Commit() renames it to `path`; a writer dropped uncommitted removes its partial
// file, unless Keep() was called.
class LineFile {
 public:
  explicit LineFile(std::filesystem::path path);
  ~LineFile();
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;

  // Appends `line` and a newline. Throws naming the partial file when the write fails.
  void Write(std::string_view line);
  void Commit();
  // Leaves the partial file in place (with its whole lines) when the writer is dropped.
  void Keep() { keep_ = true; }
  bool committed() const { return done_; }
  const std::filesystem::path& partial() const { return file_.path(); }
  uint64_t lines() const { return lines_; }

 private:
  std::filesystem::path path_;
  File file_;
  uint64_t size_ = 0, lines_ = 0;
  bool done_ = false, keep_ = false;
};

// Checks that `name` is a plain file name (no folder part, not "." or "..", not empty), so
// that files written under an output folder stay in it.
void CheckFileName(const std::string& name, const std::string& what);

}  // namespace nphand

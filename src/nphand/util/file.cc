#include "nphand/util/file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "nphand/util/check.h"

namespace nphand {
namespace {

const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "a special file";
}

struct stat StatOf(int fd, const std::filesystem::path& path) {
  struct stat info {};
  NPHAND_THROW_CHECK(::fstat(fd, &info) == 0, path.string(), ": cannot read its status (", std::strerror(errno), ")");
  return info;
}

}  // namespace

File File::OpenRegular(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  NPHAND_THROW_CHECK(fd >= 0, path.string(), ": cannot open (", std::strerror(errno), ")");
  File file(fd, path);
  const struct stat info = StatOf(fd, path);
  NPHAND_THROW_CHECK(S_ISREG(info.st_mode), path.string(), ": is ", KindOf(info.st_mode), ", not a file");
  return file;
}

File File::OpenLocked(const std::filesystem::path& path) {
  // A writer that finishes renames its locked file away; one that waited on that name then
  // holds a lock on a file that no longer has it, so it tries again on the new file.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NONBLOCK | O_CLOEXEC, 0644);
    NPHAND_THROW_CHECK(fd >= 0, path.string(), ": cannot open for writing (", std::strerror(errno), ")");
    File file(fd, path);
    const struct stat info = StatOf(fd, path);
    NPHAND_THROW_CHECK(S_ISREG(info.st_mode), path.string(), ": is ", KindOf(info.st_mode), ", not a file");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      NPHAND_THROW_CHECK(error != EWOULDBLOCK, path.string(),
                         ": another nphand process is writing it (the file is locked); wait for it to finish or "
                         "write elsewhere");
      NPHAND_THROW(path.string(), ": cannot lock (", std::strerror(error), ")");
    }
    struct stat named {};
    if (::stat(path.c_str(), &named) == 0 && named.st_dev == info.st_dev && named.st_ino == info.st_ino) return file;
  }
  NPHAND_THROW(path.string(), ": keeps being replaced while nphand tries to lock it");
}

File::~File() { Close(); }

File::File(File&& other) noexcept { *this = std::move(other); }

File& File::operator=(File&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
  }
  return *this;
}

uint64_t File::Size() const { return static_cast<uint64_t>(StatOf(fd_, path_).st_size); }

bool File::ReadAt(uint64_t offset, std::span<uint8_t> bytes) const {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    NPHAND_THROW_CHECK(n >= 0, path_.string(), ": read failed (", std::strerror(errno), ")");
    if (n == 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

void File::WriteAt(uint64_t offset, std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    NPHAND_THROW_CHECK(n > 0, path_.string(), ": write failed (", std::strerror(errno), ")");
    done += static_cast<size_t>(n);
  }
}

void File::Append(std::span<const uint8_t> bytes) { WriteAt(Size(), bytes); }

void File::Truncate(uint64_t size) {
  NPHAND_THROW_CHECK(::ftruncate(fd_, static_cast<off_t>(size)) == 0, path_.string(), ": cannot truncate (",
                     std::strerror(errno), ")");
}

void File::Sync() {
  NPHAND_THROW_CHECK(::fsync(fd_) == 0, path_.string(), ": flush failed (", std::strerror(errno), ")");
}

void File::Close() {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
}

void CheckOutputFile(const std::filesystem::path& path, const std::string& what) {
  NPHAND_THROW_CHECK(!path.empty(), what, ": the output path is empty");
  const std::string name = path.filename().string();
  NPHAND_THROW_CHECK(!name.empty() && name != "." && name != "..", what, " '", path.string(),
                     "': names a folder, not a file");
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  NPHAND_THROW_CHECK(!std::filesystem::exists(status) || std::filesystem::is_regular_file(status), what, " '",
                     path.string(), "': is ",
                     std::filesystem::is_directory(status) ? "a folder" : "not a regular file", ", not a file to write");
  CheckOutputFolder(path.has_parent_path() ? path.parent_path() : std::filesystem::path("."), what);
}

void CheckOutputFolder(const std::filesystem::path& path, const std::string& what) {
  NPHAND_THROW_CHECK(!path.empty(), what, ": the output folder is empty");
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    std::filesystem::create_directories(path, ec);
    NPHAND_THROW_CHECK(!ec, what, " '", path.string(), "': cannot create the folder (", ec.message(), ")");
  }
  NPHAND_THROW_CHECK(std::filesystem::is_directory(path, ec), what, " '", path.string(), "': is a file, not a folder");
  NPHAND_THROW_CHECK(::access(path.c_str(), W_OK | X_OK) == 0, what, " '", path.string(),
                     "': cannot write in this folder (", std::strerror(errno), ")");
}

namespace {

// The file `path` reaches, as far as it exists: its device and inode when it does,
// otherwise its absolute path with symlinks and "." and ".." resolved.
struct Identity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::filesystem::path resolved;
  bool operator==(const Identity& other) const {
    return exists == other.exists && (exists ? device == other.device && inode == other.inode : resolved == other.resolved);
  }
};

Identity IdentityOf(const std::filesystem::path& path) {
  Identity identity;
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0) {
    identity.exists = true;
    identity.device = info.st_dev;
    identity.inode = info.st_ino;
    return identity;
  }
  std::error_code ec;
  identity.resolved = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
  if (ec) identity.resolved = std::filesystem::absolute(path).lexically_normal();
  return identity;
}

std::string Describe(const NamedPath& named) { return named.what + " '" + named.path.string() + "'"; }

}  // namespace

void CheckOutputsApart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
  std::vector<Identity> output_ids;
  for (const NamedPath& output : outputs) output_ids.push_back(IdentityOf(output.path));
  for (size_t o = 0; o < outputs.size(); ++o) {
    for (size_t p = 0; p < o; ++p) {
      NPHAND_THROW_CHECK(!(output_ids[o] == output_ids[p]), Describe(outputs[o]), " and ", Describe(outputs[p]),
                         " are the same file: one output would overwrite the other");
    }
  }
  for (const NamedPath& input : inputs) {
    if (input.path.empty()) continue;
    const Identity id = IdentityOf(input.path);
    const Identity folder = IdentityOf(input.path.has_parent_path() ? input.path.parent_path() : ".");
    const std::string extension = input.path.extension().string();
    for (size_t o = 0; o < outputs.size(); ++o) {
      const NamedPath& output = outputs[o];
      if (output.extensions.empty()) {
        NPHAND_THROW_CHECK(!(id == output_ids[o]), Describe(output), " is ", Describe(input),
                           ": writing it would destroy an input; write elsewhere");
      } else {
        const bool written_here = std::find(output.extensions.begin(), output.extensions.end(), extension) !=
                                  output.extensions.end();
        NPHAND_THROW_CHECK(!written_here || !(folder == output_ids[o]), Describe(input), " lies in ", Describe(output),
                           ", where this command writes its ", extension,
                           " files: writing there could destroy an input; write elsewhere");
      }
    }
  }
}

LineFile::LineFile(std::filesystem::path path) : path_(std::move(path)), file_(File::OpenLocked(path_.string() + ".partial")) {
  file_.Truncate(0);
}

LineFile::~LineFile() {
  if (done_ || keep_) return;
  std::error_code ec;
  std::filesystem::remove(file_.path(), ec);
}

void LineFile::Write(std::string_view line) {
  std::string bytes;
  bytes.reserve(line.size() + 1);
  bytes.append(line).push_back('\n');
  try {
    file_.WriteAt(size_, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
  } catch (const Error&) {
    // Whole lines only: what part of this line reached the disk goes again.
    if (::ftruncate(file_.fd(), static_cast<off_t>(size_)) == 0) throw;
    NPHAND_THROW(file_.path().string(), ": a write failed and its cut-off last line could not be removed (",
                 std::strerror(errno), ")");
  }
  size_ += bytes.size();
  ++lines_;
}

void LineFile::Commit() {
  NPHAND_CHECK(!done_, "a LineFile is committed once");
  file_.Sync();
  std::error_code ec;
  std::filesystem::rename(file_.path(), path_, ec);
  NPHAND_THROW_CHECK(!ec, path_.string(), ": cannot rename ", file_.path().string(), " into place (", ec.message(), ")");
  done_ = true;
  file_.Close();
}

void CheckFileName(const std::string& name, const std::string& what) {
  NPHAND_THROW_CHECK(!name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
                         name.find('\0') == std::string::npos,
                     what, " '", name, "': must be a file name, not a path (no '/', not '.' or '..')");
}

}  // namespace nphand

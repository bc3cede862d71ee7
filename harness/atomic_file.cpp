#include "harness/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace hil::harness {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, const std::string& step, int error) {
  throw std::runtime_error("cannot write " + path + ": " + step + ": " + std::strerror(error));
}

// Closes the descriptor and removes the temporary file unless the rename
// happened, so a failed write leaves nothing behind.
class TempFile {
 public:
  TempFile(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!renamed_) ::unlink(path_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  /// Closes the descriptor; the errno of a failed close, 0 on success.
  int close() {
    const int rc = ::close(fd_);
    fd_ = -1;
    return rc == 0 ? 0 : errno;
  }
  void renamed() { renamed_ = true; }

 private:
  int fd_;
  std::string path_;
  bool renamed_ = false;
};

}  // namespace

void write_file_atomically(const std::string& path, std::string_view bytes) {
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // mkstemp in the target's folder: rename() is atomic only within one file
  // system, and a name nobody else can have picked keeps parallel writers apart.
  std::string pattern = (folder / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) fail(path, "cannot create a temporary file in " + folder.string(), errno);
  TempFile temp(fd, pattern);
  // mkstemp makes the file 0600; a report keeps the mode of the file it
  // replaces, or gets the usual rw-r--r-- (reading the umask would change
  // it for every thread for a moment).
  struct stat existing {};
  ::fchmod(temp.fd(), ::stat(path.c_str(), &existing) == 0 ? existing.st_mode & 07777 : 0644);

  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(temp.fd(), bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(path, "write", errno);
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(temp.fd()) != 0) fail(path, "fsync", errno);
  if (const int error = temp.close(); error != 0) fail(path, "close", error);
  if (::rename(temp.path().c_str(), path.c_str()) != 0) fail(path, "rename", errno);
  temp.renamed();
  // The rename itself lives in the folder's entry; without this a power cut
  // could bring back the old file (best effort: some file systems refuse it).
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace hil::harness

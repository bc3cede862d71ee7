#include "link/capture/capture_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <utility>

namespace hil::link {

std::optional<CaptureFile> CaptureFile::open(const std::filesystem::path& path, Mode mode,
                                             std::error_code& ec) {
  ec.clear();
  const int how = mode == Mode::append ? O_APPEND : O_TRUNC;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | how | O_CLOEXEC, 0644);
  if (fd < 0) {
    ec.assign(errno, std::generic_category());
    return std::nullopt;
  }
  return CaptureFile(fd);
}

CaptureFile::CaptureFile(CaptureFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), error_(other.error_) {}

CaptureFile::~CaptureFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool CaptureFile::write(protocol::ByteView bytes) {
  const std::uint8_t* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (!error_) error_.assign(errno, std::generic_category());
      return false;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace hil::link

#pragma once
// The file a capture writes: every record goes to the kernel with write(2)
// before the call returns, so nothing waits in a user-space buffer to be
// lost if hil crashes.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <system_error>

#include "protocol/common/bytes.hpp"

namespace hil::link {

class CaptureFile {
 public:
  /// `truncate` starts the file empty; `append` adds to its end, each
  /// write whole even when other writers append to the same path.
  enum class Mode : std::uint8_t { truncate, append };

  /// Opens `path`, creating it if needed; nullopt and `ec` set when it cannot.
  static std::optional<CaptureFile> open(const std::filesystem::path& path, Mode mode,
                                         std::error_code& ec);
  CaptureFile(CaptureFile&& other) noexcept;
  CaptureFile& operator=(CaptureFile&&) = delete;
  CaptureFile(const CaptureFile&) = delete;
  CaptureFile& operator=(const CaptureFile&) = delete;
  ~CaptureFile();

  /// Writes all of `bytes` (again after a signal or a short write); false
  /// when the system refuses, the first such error kept.
  bool write(protocol::ByteView bytes);
  /// The first write error, if any.
  std::error_code error() const { return error_; }

 private:
  explicit CaptureFile(int fd) : fd_(fd) {}

  int fd_ = -1;
  std::error_code error_;
};

}  // namespace hil::link

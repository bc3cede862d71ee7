#pragma once
// The one error of a hil file that cannot load: a world, a fault profile, a
// behaviours file or a scenario.

#include <stdexcept>
#include <string>

namespace hil::config {

/// what() reads "FILE:LINE:COLUMN: MESSAGE", e.g. "release.yaml:12:9: step
/// 3: unknown LOGI action 'pres FWD' (expected connect, disconnect, ...)",
/// or "FILE: MESSAGE" when there is no position (a file that cannot be
/// read). Line and column count from 1; 0 when unknown. message() is the
/// text after the position, for a loader that reports an embedded file's
/// problem at its own position.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string file, int line, int column, std::string message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

}  // namespace hil::config

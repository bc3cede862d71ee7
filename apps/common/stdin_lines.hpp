#pragma once
// Standard input read line by line on the program's io_context, so the
// session keeps running while nobody types: through the reactor for a
// terminal, pipe or socket, at once for a regular file.

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

namespace hil::apps {

class StdinLines {
 public:
  struct Handlers {
    /// One line, without its '\n'.
    std::function<void(std::string line)> line;
    /// End of input (Ctrl-D, the pipe closed, or stdin cannot be read), with
    /// a last line that had no '\n' (empty if none).
    std::function<void(std::string rest)> end;
    /// Asked before each line and each read: false stops reading.
    std::function<bool()> more;
  };

  StdinLines(asio::io_context& io, Handlers handlers);
  ~StdinLines();
  StdinLines(const StdinLines&) = delete;
  StdinLines& operator=(const StdinLines&) = delete;

  /// Begins reading (the first line comes on a later turn of the io_context).
  void start();
  /// Stops reading and gives stdin back as it was (blocking).
  void stop();

 private:
  void read_all();
  void read_some();
  void take(std::string_view bytes);
  void ended();
  bool more() const { return !handlers_.more || handlers_.more(); }

  asio::io_context& io_;
  Handlers handlers_;
  int stdin_flags_ = -1;
  std::unique_ptr<asio::posix::stream_descriptor> input_;
  std::array<char, 4096> buf_{};
  std::string partial_;
  bool ended_ = false;
};

}  // namespace hil::apps

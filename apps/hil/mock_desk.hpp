#pragma once
// What a person at the desk sees and types while `hil mock` runs: the
// status line redrawn in place under the log, and desk commands on stdin
// (a parcel in front of a car, a fault, a hang-up, picking the car up).

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/streambuf.hpp>

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "mocks/car.hpp"
#include "mocks/server.hpp"

namespace hil::apps {

/// One mock car and the server it listens with.
struct RunningCar {
  std::unique_ptr<mocks::MockCar> car;
  std::unique_ptr<mocks::MockServer> server;
};

/// The terminal's status line: redrawn in place; log lines are printed above it.
class StatusLine {
 public:
  explicit StatusLine(bool enabled) : enabled_(enabled) {}
  void log(const std::string& line);
  void show(const std::string& text);
  void end();
  bool enabled() const { return enabled_; }

 private:
  bool enabled_;
  std::string last_;
};

/// The status line's text: one car's pose, firmware and client, or the
/// fleet's count of cars and clients; then frames and faults of all cars.
std::string status_text(const std::vector<RunningCar>& cars);

/// Desk commands typed while the cars run: drop a parcel in front of a car,
/// take it away, fail the car, hang up on the client, pick the car up.
class DeskConsole {
 public:
  /// Throws std::system_error when stdin cannot be read asynchronously.
  DeskConsole(asio::io_context& io, std::vector<RunningCar>& cars,
              std::function<void(const std::string&)> say);
  ~DeskConsole() { stop(); }
  DeskConsole(const DeskConsole&) = delete;
  DeskConsole& operator=(const DeskConsole&) = delete;

  /// Whether desk commands can be read: stdin is a terminal this process
  /// owns (not a background job), or `forced` (a pipe, for scripts).
  static bool available(bool forced);
  static std::string help();

  void start();
  void stop();

 private:
  void read();
  void run(const std::string& line);
  void drop_parcel(std::istringstream& in);
  void clear_parcels();
  void place(std::istringstream& in);
  void select(std::istringstream& in);
  RunningCar& selected() { return cars_.at(selected_); }

  int stdin_flags_;
  asio::posix::stream_descriptor input_;
  asio::streambuf buffer_;
  std::vector<RunningCar>& cars_;
  std::function<void(const std::string&)> say_;
  std::size_t selected_ = 0;
  std::map<std::size_t, std::vector<std::size_t>> parcels_;
};

}  // namespace hil::apps

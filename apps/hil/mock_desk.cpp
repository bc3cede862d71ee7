#include "apps/hil/mock_desk.hpp"

#include <sys/ioctl.h>
#include <unistd.h>
#include <asio/read_until.hpp>

#include <fcntl.h>

#include <cmath>
#include <csignal>
#include <iostream>
#include <numbers>
#include <sstream>

namespace hil::apps {
namespace {

// A line longer than the terminal would wrap and break the redraw in place.
std::string fit_to_terminal(const std::string& text) {
  winsize w{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) != 0 || w.ws_col == 0) return text;
  std::string out;
  std::size_t columns = 0;
  for (const char c : text) {
    const bool starts_character = (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    if (starts_character && ++columns >= w.ws_col) break;
    out += c;
  }
  return out;
}

}  // namespace

void StatusLine::log(const std::string& line) {
  if (enabled_) std::cout << "\r\033[K";
  std::cout << line << '\n';
  if (enabled_) std::cout << last_;
  std::cout << std::flush;
}

void StatusLine::show(const std::string& text) {
  if (!enabled_) return;
  last_ = fit_to_terminal(text);
  std::cout << "\r\033[K" << text << std::flush;
}

void StatusLine::end() {
  if (enabled_ && !last_.empty()) std::cout << '\n' << std::flush;
  last_.clear();
  enabled_ = false;
}

std::string status_text(const std::vector<RunningCar>& cars) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  std::uint64_t in = 0;
  std::uint64_t sent = 0;
  std::uint64_t bad = 0;
  std::uint64_t faults = 0;
  std::size_t clients = 0;
  for (const auto& c : cars) {
    const auto& s = c.car->firmware().stats();
    in += s.frames_in;
    sent += s.frames_out;
    bad += s.bad_frames;
    faults += c.server->faults_injected();
    if (c.server->client_connected()) ++clients;
  }
  if (cars.size() == 1) {
    auto& c = cars.front();
    const auto pose = c.car->vehicle().pose();
    out << c.car->name() << " x " << pose.x_m << " y " << pose.y_m << " hdg "
        << static_cast<int>(std::lround(pose.heading_rad * 180 / std::numbers::pi)) << "° | "
        << c.car->firmware().summary() << " | client "
        << (c.server->client_connected() ? "yes" : "no");
  } else {
    out << cars.size() << " cars | " << clients << " client(s)";
  }
  out << " | frames in " << in << " out " << sent << " bad " << bad << " | faults " << faults;
  return out.str();
}

DeskConsole::DeskConsole(asio::io_context& io, std::vector<RunningCar>& cars,
                         std::function<void(const std::string&)> say)
    : stdin_flags_(::fcntl(STDIN_FILENO, F_GETFL)),
      input_(io, ::dup(STDIN_FILENO)),
      cars_(cars),
      say_(std::move(say)) {}

bool DeskConsole::available(bool forced) {
  if (forced) return true;
  return ::isatty(STDIN_FILENO) != 0 && ::tcgetpgrp(STDIN_FILENO) == ::getpgrp();
}

std::string DeskConsole::help() {
  return "commands: obstacle [CM] (a parcel CM ahead of the car's front, default 15) | clear "
         "(take the parcels away) | fault | recover | hangup (close the client's connection) | "
         "place X Y [DEG] | car N (which car the commands act on) | help";
}

void DeskConsole::start() {
  // Sent to `hil mock` put in the background later: the read fails
  // instead of stopping the process, and the cars run on.
  std::signal(SIGTTIN, SIG_IGN);
  read();
}

void DeskConsole::stop() {
  if (!input_.is_open()) return;
  std::error_code ec;
  input_.close(ec);
  // Asio made the shared file description non-blocking; the shell that
  // gets the terminal back expects it as it was.
  if (stdin_flags_ != -1) ::fcntl(STDIN_FILENO, F_SETFL, stdin_flags_);
}

void DeskConsole::read() {
  asio::async_read_until(input_, buffer_, '\n', [this](std::error_code ec, std::size_t n) {
    if (ec) return;  // stdin closed: the cars run on
    std::string line(asio::buffers_begin(buffer_.data()),
                     asio::buffers_begin(buffer_.data()) + static_cast<std::ptrdiff_t>(n));
    buffer_.consume(n);
    run(line);
    read();
  });
}

void DeskConsole::run(const std::string& line) {
  std::istringstream in(line);
  std::string word;
  if (!(in >> word)) return;
  auto& firmware = selected().car->firmware();
  const std::string who = selected().car->name();
  if (word == "help") {
    say_(help());
  } else if (word == "obstacle") {
    drop_parcel(in);
  } else if (word == "clear") {
    clear_parcels();
  } else if (word == "fault") {
    firmware.arm(mocks::Behaviour{"desk fault", {}, mocks::EnterFault{}});
    say_(who + ": fault state");
  } else if (word == "recover") {
    firmware.arm(mocks::Behaviour{"desk recover", {}, mocks::ClearFault{}});
    say_(who + ": fault cleared");
  } else if (word == "hangup") {
    firmware.arm(mocks::Behaviour{"desk hangup", {}, mocks::CloseConnection{}});
    say_(who + (firmware.connected() ? ": closing the client's connection" : ": no client"));
  } else if (word == "place") {
    place(in);
  } else if (word == "car") {
    select(in);
  } else {
    say_("unknown command '" + word + "' (" + help() + ")");
  }
}

void DeskConsole::drop_parcel(std::istringstream& in) {
  double cm = 15;
  if (!(in >> cm)) cm = 15;
  if (cm < 0 || cm > 400) {
    say_("obstacle: CM must be 0..400");
    return;
  }
  mocks::MockCar& car = *selected().car;
  auto& vehicle = car.vehicle();
  const auto footprint = vehicle.chassis().footprint();
  const double front_m = footprint.center_ahead_m + footprint.length_m / 2;
  const double depth_m = 0.10;
  const auto center = vehicle.pose().to_arena({front_m + cm / 100 + depth_m / 2, 0});
  const auto index = car.world().add_obstacle(
      sim::BoxObstacle{"parcel", center, depth_m, 0.30, vehicle.pose().heading_rad});
  parcels_[selected_].push_back(index);
  say_(car.name() + ": parcel dropped " + std::to_string(static_cast<int>(cm)) + " cm ahead");
}

void DeskConsole::clear_parcels() {
  mocks::MockCar& car = *selected().car;
  std::size_t lifted = 0;
  for (const auto index : parcels_[selected_])
    if (car.world().remove_obstacle(index)) ++lifted;
  parcels_[selected_].clear();
  say_(car.name() + ": " + std::to_string(lifted) + " parcel(s) taken away");
}

void DeskConsole::place(std::istringstream& in) {
  double x = 0;
  double y = 0;
  double deg = 0;
  if (!(in >> x >> y)) {
    say_("place: give X Y in metres and optionally a heading in degrees");
    return;
  }
  in >> deg;
  selected().car->vehicle().place(sim::Pose{x, y, deg * std::numbers::pi / 180});
  say_(selected().car->name() + ": placed");
}

void DeskConsole::select(std::istringstream& in) {
  std::size_t n = 0;
  if (!(in >> n) || n >= cars_.size()) {
    say_("car: give a number from 0 to " + std::to_string(cars_.size() - 1));
    return;
  }
  selected_ = n;
  say_("commands now act on " + cars_.at(n).car->name());
}

}  // namespace hil::apps

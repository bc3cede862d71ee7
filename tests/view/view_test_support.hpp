#pragma once
// `hil mock logi --view 0` running in the background for the live view's
// process and browser tests: its ports, its JSON API, and logi-client runs
// that drive the car.

#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <functional>
#include <optional>
#include <regex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::view::test {

using nlohmann::json;

/// Waits up to `limit` for `condition`, checking every 50 ms.
inline bool wait_until(const std::function<bool()>& condition,
                       std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return true;
}

class ViewedMock {
 public:
  explicit ViewedMock(std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"mock", "logi", "--port", "0", "--view", "0", "--no-status"};
    args.insert(args.end(), extra.begin(), extra.end());
    process_ = std::make_unique<hil::test::HilProcess>(args);
    const auto car = process_->wait_for_line("connect to tcp://");
    const auto view = process_->wait_for_line("view: http://127.0.0.1:");
    if (!car || !view) return;
    std::smatch m;
    if (std::regex_search(*car, m, std::regex(R"(tcp://127\.0\.0\.1:(\d+))"))) car_port_ = m[1];
    if (std::regex_search(*view, m, std::regex(R"(http://127\.0\.0\.1:(\d+)/)"))) {
      view_port_ = std::stoi(m[1]);
      url_ = m[0];
    }
  }
  ~ViewedMock() {
    if (process_) process_->interrupt();
  }

  bool ready() const { return view_port_ > 0 && !car_port_.empty(); }
  const std::string& car_port() const { return car_port_; }
  int view_port() const { return view_port_; }
  const std::string& url() const { return url_; }
  hil::test::HilProcess& process() { return *process_; }

  httplib::Client client() const {
    httplib::Client c("127.0.0.1", view_port_);
    c.set_read_timeout(10, 0);
    c.set_connection_timeout(5, 0);
    return c;
  }
  /// The first car of GET /api/state (null when the request failed).
  json state() const {
    auto c = client();
    const auto res = c.Get("/api/state");
    if (!res || res->status != 200) return nullptr;
    return json::parse(res->body)["cars"][0];
  }
  /// POST /api/<action>: the status and the JSON answer.
  std::pair<int, json> post(const std::string& action, const json& body) const {
    auto c = client();
    const auto res = c.Post(("/api/" + action).c_str(), body.dump(), "application/json");
    if (!res) return {0, nullptr};
    return {res->status, json::parse(res->body, nullptr, false)};
  }

  /// Runs logi-client against the car with these actions; its output.
  std::string drive(const std::vector<std::string>& actions) const {
    std::vector<std::string> args{"--port", car_port_, "--continue-on-error"};
    args.insert(args.end(), actions.begin(), actions.end());
    hil::test::HilProcess client(LOGI_CLIENT_BINARY, args);
    client.wait_exit(std::chrono::seconds(30));
    return client.output();
  }

 private:
  std::unique_ptr<hil::test::HilProcess> process_;
  std::string car_port_;
  int view_port_ = 0;
  std::string url_;
};

inline double distance_between(const json& a, const json& b) {
  return std::hypot(a["x"].get<double>() - b["x"].get<double>(),
                    a["y"].get<double>() - b["y"].get<double>());
}

}  // namespace hil::view::test

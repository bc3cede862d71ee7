#pragma once
// A headless Chromium steered through chromedriver's WebDriver API, for the
// browser tests of the live view and of the report pages. Tests skip when
// either program is missing (browser_missing()).

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <limits>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "tests/view/view_test_support.hpp"

namespace hil::view::test {

inline constexpr const char* kChromium = "/usr/bin/chromium";
inline constexpr const char* kChromedriver = "/usr/bin/chromedriver";

inline int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), size) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    ::close(fd);
    return 0;
  }
  ::close(fd);
  return ntohs(address.sin_port);
}

inline std::string base64_decode(const std::string& text) {
  static const std::string kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned value = 0;
  int bits = 0;
  for (const char c : text) {
    const auto index = kAlphabet.find(c);
    if (index == std::string::npos) continue;  // padding, line breaks
    value = (value << 6) | static_cast<unsigned>(index);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((value >> bits) & 0xFF);
    }
  }
  return out;
}

// One WebDriver session on a headless Chromium.
class Browser {
 public:
  Browser() {
    port_ = free_port();
    char profile[] = "/tmp/hil-view-chromium-XXXXXX";
    if (::mkdtemp(profile) == nullptr) return;
    profile_ = profile;
    driver_ = std::make_unique<hil::test::HilProcess>(
        kChromedriver, std::vector<std::string>{"--port=" + std::to_string(port_)});
    if (!driver_->wait_for_line("started successfully")) return;
    const json flags = {"--headless",
                        "--no-sandbox",
                        "--disable-gpu",
                        "--disable-quic",
                        "--no-first-run",
                        "--disable-background-networking",
                        "--disable-sync",
                        "--disable-component-update",
                        "--user-data-dir=" + profile_,
                        "--window-size=1400,1300"};
    const json session = call(
        "POST", "/session",
        {{"capabilities",
          {{"alwaysMatch", {{"goog:chromeOptions", {{"binary", kChromium}, {"args", flags}}}}}}}});
    if (session.contains("sessionId")) session_ = session["sessionId"];
  }
  ~Browser() {
    if (!session_.empty()) call("DELETE", "/session/" + session_, nullptr);
    driver_.reset();
    std::error_code ec;
    if (!profile_.empty()) std::filesystem::remove_all(profile_, ec);
  }

  bool ready() const { return !session_.empty(); }
  std::string log() const { return driver_ ? driver_->output() : "chromedriver did not start"; }

  void open(const std::string& url) { call("POST", path("/url"), {{"url", url}}); }
  json run(const std::string& script) {
    return call("POST", path("/execute/sync"), {{"script", script}, {"args", json::array()}});
  }
  /// The pose element's data attributes, which the page updates with every
  /// snapshot it draws.
  json drawn() {
    return run(
        "const e = document.getElementById('pose'); return e ? Object.assign({}, e.dataset) : "
        "null;");
  }
  void click(const std::string& css) {
    const json element =
        call("POST", path("/element"), {{"using", "css selector"}, {"value", css}});
    ASSERT_TRUE(element.is_object()) << css << ": " << element;
    const std::string id = element.begin().value().get<std::string>();
    call("POST", path("/element/" + id + "/click"), json::object());
  }
  std::string screenshot_png() {
    const json shot = call("GET", path("/screenshot"), nullptr);
    return shot.is_string() ? base64_decode(shot.get<std::string>()) : std::string();
  }
  /// Takes a screenshot, expects a real PNG, and writes it to `file` (for a
  /// person to look at the page CI saw).
  void save_screenshot(const char* file) {
    const std::string png = screenshot_png();
    ASSERT_GT(png.size(), 1000U);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    std::ofstream(file, std::ios::binary) << png;
    std::printf("screenshot: %s\n", file);
  }

 private:
  std::string path(const std::string& rest) const { return "/session/" + session_ + rest; }
  // The "value" of a WebDriver answer (the whole answer for a new session).
  json call(const std::string& method, const std::string& url, const json& body) {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(60, 0);
    httplib::Result res = method == "GET" ? c.Get(url.c_str())
                          : method == "DELETE"
                              ? c.Delete(url.c_str())
                              : c.Post(url.c_str(), body.dump(), "application/json");
    if (!res) return nullptr;
    const json answer = json::parse(res->body, nullptr, false);
    if (!answer.is_object() || !answer.contains("value")) return nullptr;
    return answer["value"];
  }

  int port_ = 0;
  std::string profile_;
  std::string session_;
  std::unique_ptr<hil::test::HilProcess> driver_;
};

inline double number(const json& dataset, const char* key) {
  if (!dataset.is_object() || !dataset.contains(key) || !dataset[key].is_string())
    return std::numeric_limits<double>::quiet_NaN();
  try {
    return std::stod(dataset[key].get<std::string>());
  } catch (const std::exception&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

/// Why a browser test cannot run here, or empty when it can.
inline std::string browser_missing() {
  if (std::filesystem::exists(kChromium) && std::filesystem::exists(kChromedriver)) return {};
  return std::string("needs Chromium and chromedriver (") + kChromium + ", " + kChromedriver +
         "; Debian packages chromium and chromium-driver, ci/install-deps.sh)";
}

}  // namespace hil::view::test

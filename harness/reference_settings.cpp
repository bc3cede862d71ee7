#include "harness/reference_settings.hpp"

#include "base/duration.hpp"

#include <algorithm>
#include <charconv>
#include <functional>
#include <stdexcept>
#include <utility>

#include "link/faults/profile_yaml.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::harness {
namespace {

using link::Duration;

// The client libraries' options a scenario may change, by name. Values come
// from YAML as texts (a list as an array of texts).

using Json = nlohmann::json;

template <class Config>
struct Option {
  ReferenceSetting doc;
  /// Sets the option, or says what a value must be.
  std::function<std::optional<std::string>(Config&, const Json&)> set;
};

std::string text_of(const Json& v) {
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::optional<long long> whole_of(const Json& v) {
  if (!v.is_string()) return std::nullopt;
  const auto& t = v.get_ref<const std::string&>();
  long long n = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), n);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
  return n;
}

template <class Config>
Option<Config> duration_option(std::string name, Duration Config::*member, std::string what,
                               bool zero_allowed = false) {
  const std::string takes = zero_allowed ? "a duration with a unit (5s; 0s: never)"
                                         : "a duration above 0 with a unit (800ms, 2s)";
  return {{std::move(name), takes, std::move(what)},
          [member, zero_allowed, takes](Config& c, const Json& v) -> std::optional<std::string> {
            const auto d = v.is_string() ? hil::parse_duration(v.get<std::string>())
                                         : std::optional<Duration>{};
            if (!d || (*d == Duration(0) && !zero_allowed)) return takes;
            c.*member = *d;
            return std::nullopt;
          }};
}

template <class Config, class Int>
Option<Config> count_option(std::string name, Int Config::*member, long long min, long long max,
                            std::string what) {
  const std::string takes = "a whole number " + std::to_string(min) + ".." + std::to_string(max);
  return {{std::move(name), takes, std::move(what)},
          [member, min, max, takes](Config& c, const Json& v) -> std::optional<std::string> {
            const auto n = whole_of(v);
            if (!n || *n < min || *n > max) return takes;
            c.*member = static_cast<Int>(*n);
            return std::nullopt;
          }};
}

template <class Config>
Option<Config> flag_option(std::string name, bool Config::*member, std::string what) {
  return {{std::move(name), "true or false", std::move(what)},
          [member](Config& c, const Json& v) -> std::optional<std::string> {
            const std::string t = text_of(v);
            if (t == "true" || t == "yes" || t == "on") {
              c.*member = true;
            } else if (t == "false" || t == "no" || t == "off") {
              c.*member = false;
            } else {
              return "true or false";
            }
            return std::nullopt;
          }};
}

// `reconnect_delays`, the same setting for every client that has it.
template <class Config>
Option<Config> delays_option(std::vector<Duration> Config::*member) {
  const std::string takes = "a list of durations above 0, like [1s, 2s, 3s]";
  return {{"reconnect_delays", takes,
           "the waits before reconnect attempts 1, 2, 3, ...; the last repeats"},
          [member, takes](Config& c, const Json& v) -> std::optional<std::string> {
            const Json list = v.is_array() ? v : Json::array({v});
            std::vector<Duration> delays;
            for (const auto& item : list) {
              const auto d = item.is_string() ? hil::parse_duration(item.get<std::string>())
                                              : std::optional<Duration>{};
              if (!d || *d == Duration(0)) return takes;
              delays.push_back(*d);
            }
            if (delays.empty()) return takes;
            c.*member = std::move(delays);
            return std::nullopt;
          }};
}

const std::vector<Option<client::logi::ClientConfig>>& logi_options() {
  using C = client::logi::ClientConfig;
  static const std::vector<Option<C>> options = {
      duration_option("feedback_timeout", &C::feedback_timeout,
                      "how long a command waits for its FB before it times out"),
      count_option("max_retries", &C::max_retries, 0, 10,
                   "resends of SP, MD and MV:STOP after a timeout"),
      delays_option(&C::reconnect_delays),
      duration_option("stale_after", &C::stale_after,
                      "how long without a STAT before the stale warning"),
      flag_option("keepalive", &C::keepalive, "repeat the held direction's MV while it is held"),
      duration_option("keepalive_period", &C::keepalive_period,
                      "how often the held MV is repeated with keepalive"),
  };
  return options;
}

const std::vector<Option<client::wr8::ClientConfig>>& wr8_options() {
  using C = client::wr8::ClientConfig;
  static const std::vector<Option<C>> options = {
      {{"auth", "a text of exactly 10 printable characters", "the string AUTH carries"},
       [](C& c, const Json& v) -> std::optional<std::string> {
         const std::string t = text_of(v);
         const bool printable =
             std::all_of(t.begin(), t.end(), [](char ch) { return ch >= 0x20 && ch <= 0x7E; });
         if (!v.is_string() || t.size() != c.profile.auth_text.size() || !printable) {
           return "a text of exactly " + std::to_string(c.profile.auth_text.size()) +
                  " printable characters";
         }
         std::copy(t.begin(), t.end(), c.profile.auth_text.begin());
         return std::nullopt;
       }},
      duration_option("auth_timeout", &C::auth_timeout,
                      "how long the login waits for AUTH-REPLY before the connection fails"),
      duration_option("answer_timeout", &C::answer_timeout,
                      "how long a TASK or SETTINGS waits for its first answer"),
      duration_option("stale_after", &C::stale_after,
                      "how long without DATA before the live state is stale"),
      delays_option(&C::reconnect_delays),
  };
  return options;
}

const std::vector<Option<client::wr8::SvguiConfig>>& svgui_options() {
  using C = client::wr8::SvguiConfig;
  static const std::vector<Option<C>> options = {
      duration_option("login_timeout", &C::login_timeout,
                      "how long the login waits for AUTH-REPLY before the connection fails"),
      flag_option("wait_for_login", &C::wait_for_login,
                  "false: use the connection once AUTH is sent, as the real v2019 GUI does"),
      duration_option("answer_timeout", &C::answer_timeout,
                      "head: how long SET waits for an ANSWER and SET-REQUEST for its SET"),
      duration_option("send_gap", &C::send_gap,
                      "the least time between two packets sent (0: send at once)", true),
      duration_option("control_period", &C::control_period,
                      "head: how often a held CONTROL is repeated"),
      delays_option(&C::reconnect_delays),
  };
  return options;
}

const std::vector<Option<client::arduino::ClientConfig>>& arduino_options() {
  using C = client::arduino::ClientConfig;
  static const std::vector<Option<C>> options = {
      duration_option("base_timeout", &C::base_timeout,
                      "the first attempt's timeout; each retry doubles it"),
      count_option("max_retries", &C::max_retries, 0, 10, "retries after the first attempt"),
      count_option("max_bad_cs_resends", &C::max_bad_cs_resends, 0, 10,
                   "resends of one request answered NACK BAD_CS"),
      duration_option("health_check_interval", &C::health_check_interval,
                      "a PING after this long without an exchange", true),
      duration_option("reconnect_base_delay", &C::reconnect_base_delay,
                      "the wait before the first reconnect attempt; doubles after"),
      count_option("max_reconnect_attempts", &C::max_reconnect_attempts, 1, 20,
                   "failed reconnect attempts before the link is DOWN"),
      count_option("reconnect_ping_retries", &C::reconnect_ping_retries, 0, 10,
                   "retries of the PING that proves a reopened port"),
  };
  return options;
}

const std::vector<Option<client::leka::ClientConfig>>& leka_options() {
  using C = client::leka::ClientConfig;
  static const std::vector<Option<C>> options = {
      duration_option("info_timeout", &C::info_timeout,
                      "how long an info request waits for the robot's line"),
      flag_option("paced", &C::paced,
                  "keep within the robot's buffer per loop period (false: send at once)"),
      duration_option("loop_period", &C::loop_period,
                      "the robot's main-loop period the pacing follows"),
  };
  return options;
}

template <class Config>
std::optional<std::string> set_option(const std::vector<Option<Config>>& options, Config& config,
                                      const std::string& name, const Json& value) {
  for (const auto& o : options) {
    if (o.doc.name != name) continue;
    if (auto problem = o.set(config, value)) {
      return "'" + name + "' must be " + *problem + ", got '" + text_of(value) + "'";
    }
    return std::nullopt;
  }
  std::string names;
  for (const auto& o : options)
    names += (names.empty() ? "" : ", ") + o.doc.name;
  return "unknown setting '" + name + "' (this car's client takes: " + names + ")";
}

template <class Config>
Config configured(const std::vector<Option<Config>>& options, const Json& settings) {
  Config config;
  if (!settings.is_object()) throw std::invalid_argument("reference settings must be an object");
  for (const auto& [name, value] : settings.items()) {
    if (auto problem = set_option(options, config, name, value))
      throw std::invalid_argument(*problem);
  }
  return config;
}

}  // namespace

std::optional<protocol::wr8::svgui::Version> svgui_version(mocks::CarKind car,
                                                           std::string_view profile) {
  if (car != mocks::CarKind::wr8) return std::nullopt;
  return protocol::wr8::svgui::version_of_profile(profile);
}

std::vector<ReferenceSetting> reference_settings(mocks::CarKind car, std::string_view profile) {
  std::vector<ReferenceSetting> out;
  const auto docs = [&](const auto& options) {
    for (const auto& o : options)
      out.push_back(o.doc);
  };
  if (svgui_version(car, profile)) {
    docs(svgui_options());
    return out;
  }
  switch (car) {
    case mocks::CarKind::logi:
      docs(logi_options());
      break;
    case mocks::CarKind::wr8:
      docs(wr8_options());
      break;
    case mocks::CarKind::arduino:
      docs(arduino_options());
      break;
    case mocks::CarKind::leka:
      docs(leka_options());
      break;
  }
  return out;
}

std::optional<std::string> reference_setting_problem(mocks::CarKind car, const std::string& name,
                                                     const nlohmann::json& value,
                                                     std::string_view profile) {
  if (svgui_version(car, profile)) {
    client::wr8::SvguiConfig c;
    return set_option(svgui_options(), c, name, value);
  }
  switch (car) {
    case mocks::CarKind::logi: {
      client::logi::ClientConfig c;
      return set_option(logi_options(), c, name, value);
    }
    case mocks::CarKind::wr8: {
      client::wr8::ClientConfig c;
      return set_option(wr8_options(), c, name, value);
    }
    case mocks::CarKind::arduino: {
      client::arduino::ClientConfig c;
      return set_option(arduino_options(), c, name, value);
    }
    case mocks::CarKind::leka: {
      client::leka::ClientConfig c;
      return set_option(leka_options(), c, name, value);
    }
  }
  return "unknown car";
}

client::logi::ClientConfig logi_client_config(const Json& settings) {
  return configured(logi_options(), settings);
}
client::wr8::ClientConfig wr8_client_config(const Json& settings) {
  return configured(wr8_options(), settings);
}
client::wr8::SvguiConfig svgui_client_config(const Json& settings) {
  return configured(svgui_options(), settings);
}
client::arduino::ClientConfig arduino_client_config(const Json& settings,
                                                    std::string_view profile) {
  auto config = configured(arduino_options(), settings);
  config.dialect =
      protocol::arduino::dialect_named(protocol::find_car_profile("arduino", profile).name);
  return config;
}
client::leka::ClientConfig leka_client_config(const Json& settings) {
  return configured(leka_options(), settings);
}

}  // namespace hil::harness

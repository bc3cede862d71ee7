#include "control/proxy_api.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <exception>
#include <functional>
#include <new>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <variant>

#include "base/duration.hpp"
#include "base/prometheus_text.hpp"
#include "config/error.hpp"
#include "control/proxy_metrics.hpp"
#include "link/faults/profile_yaml.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::control {
namespace {

using nlohmann::json;

// Text that came from the request (names, bodies) may be any bytes: a
// reply replaces what is not UTF-8 instead of failing to write it.
std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

ApiReply json_reply(int status, const json& body) {
  ApiReply reply;
  reply.status = status;
  reply.body = dump(body);
  return reply;
}

ApiReply no_content() {
  ApiReply reply;
  reply.status = 204;
  reply.content_type.clear();
  return reply;
}

// How deep '[' and '{' nest in `text`; with `json_strings`, brackets inside
// JSON strings do not count (YAML's quoting is not followed: every bracket
// counts, which only overestimates).
std::size_t nesting_depth(std::string_view text, bool json_strings) {
  std::size_t depth = 0;
  std::size_t deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (json_strings && c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

void check_nesting(std::string_view body, bool json_strings) {
  if (nesting_depth(body, json_strings) > kMaxBodyNesting)
    throw ApiError(400, "body: nested deeper than " + std::to_string(kMaxBodyNesting) +
                            " levels (expected a flat request)");
}

// nlohmann's message without its prefix: "LINE:COL: what".
std::string parse_error_text(const json::parse_error& e) {
  std::string what = e.what();
  int line = 0;
  int column = 0;
  const auto at = what.find("at line ");
  if (at != std::string::npos &&
      std::sscanf(what.c_str() + at, "at line %d, column %d", &line, &column) == 2) {
    const auto colon = what.find(": ", at);
    const std::string rest = colon == std::string::npos ? what : what.substr(colon + 2);
    return std::to_string(line) + ":" + std::to_string(column) + ": " + rest;
  }
  const auto close = what.find("] ");
  return close == std::string::npos ? what : what.substr(close + 2);
}

json parse_json_body(const ApiRequest& request) {
  check_nesting(request.body, true);
  try {
    return json::parse(request.body);
  } catch (const json::parse_error& e) {
    throw ApiError(400, "body: not JSON (" + parse_error_text(e) + ")");
  } catch (const json::exception& e) {
    // A number too large for a double ("8e899") is refused while parsing.
    const std::string what = e.what();
    const auto close = what.find("] ");
    throw ApiError(400, "body: not JSON (" +
                            (close == std::string::npos ? what : what.substr(close + 2)) + ")");
  }
}

std::string json_type_name(const json& value) {
  return value.is_number()    ? "a number"
         : value.is_string()  ? "a string"
         : value.is_boolean() ? "true/false"
         : value.is_null()    ? "null"
         : value.is_array()   ? "an array"
                              : "an object";
}

json parse_object_body(const ApiRequest& request) {
  json body = parse_json_body(request);
  if (!body.is_object())
    throw ApiError(400, "body: expected an object ({...}), got " + json_type_name(body));
  return body;
}

// An object body, or {} when the body is empty (the endpoints whose
// fields are all optional).
json parse_optional_object_body(const ApiRequest& request) {
  if (request.body.find_first_not_of(" \t\r\n") == std::string::npos) return json::object();
  return parse_object_body(request);
}

std::optional<std::string> optional_string(const json& body, const std::string& field) {
  const auto it = body.find(field);
  if (it == body.end() || it->is_null()) return std::nullopt;
  if (!it->is_string())
    throw ApiError(400, field + ": expected a string, got " + json_type_name(*it));
  return it->get<std::string>();
}

std::optional<bool> optional_bool(const json& body, const std::string& field) {
  const auto it = body.find(field);
  if (it == body.end() || it->is_null()) return std::nullopt;
  if (!it->is_boolean())
    throw ApiError(400, field + ": expected true or false, got " + json_type_name(*it));
  return it->get<bool>();
}

// ---- what the endpoints show ----

json direction_pair(const std::array<std::uint64_t, 2>& values) {
  return {{"to_car", values[static_cast<std::size_t>(link::Direction::to_car)]},
          {"to_client", values[static_cast<std::size_t>(link::Direction::to_client)]}};
}

json link_json(const std::string& route, const link::ProxyLinkInfo& info) {
  json faults = json::object();
  for (std::size_t k = 0; k < info.faults.size(); ++k) {
    if (info.faults[k] != 0)
      faults[std::string(link::to_string(static_cast<link::FaultKind>(k)))] = info.faults[k];
  }
  const auto delivered = [&](link::Direction d) {
    return info.stats.bytes_delivered[static_cast<std::size_t>(d)];
  };
  return {{"route", route},
          {"link", info.number},
          {"client", info.client},
          {"car", info.car},
          {"opened_at_ms", link::to_ms(info.opened_at)},
          {"open", info.open},
          {"close_reason", info.close_reason},
          {"bytes",
           {{"to_car", delivered(link::Direction::to_car)},
            {"to_client", delivered(link::Direction::to_client)}}},
          {"frames", direction_pair(info.frames)},
          {"bad_frames", direction_pair(info.bad_frames)},
          {"faults", faults}};
}

json route_links_json(const ProxyHub::Route& route) {
  json links = json::array();
  if (route.proxy) {
    for (const auto& info : route.proxy->links())
      links.push_back(link_json(route.spec.name, info));
  }
  return links;
}

json toxics_json(const ProxyHub::Route& route) {
  json toxics = json::array();
  for (const Toxic& toxic : route.spec.toxics)
    toxics.push_back(to_json(toxic));
  return toxics;
}

// ---- requests ----

// One request as the handlers see it: the path's decoded segments that
// the pattern left open, and the hub.
struct Call {
  ProxyHub& hub;
  const ApiRequest& request;
  const ApiInfo& info;
  std::vector<std::string> params;
};

std::size_t link_number(const std::string& text) {
  std::size_t number = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (ec != std::errc() || end != text.data() + text.size() || number == 0)
    throw ApiError(400, "link: '" + text + "' is not a link number (expected 1, 2, ...)");
  return number;
}

link::DirectionFilter stall_direction(const json& body) {
  const auto text = optional_string(body, "direction");
  if (!text) return link::DirectionFilter::both;
  if (const auto filter = link::kDirectionFilterNames.parse(*text)) return *filter;
  throw ApiError(400, "direction: '" + *text + "' is not a direction (expected " +
                          std::string(link::kDirectionFilterNames.list(" or ")) + ")");
}

link::Duration stall_duration(const json& body) {
  const auto it = body.find("duration_ms");
  if (it == body.end())
    throw ApiError(400, "duration_ms: missing (expected how long to stall, in milliseconds)");
  if (!it->is_number())
    throw ApiError(400,
                   "duration_ms: expected a number of milliseconds, got " + json_type_name(*it));
  const double ms = it->get<double>();
  // A day at most: longer is surely a unit mistake, and keeps the
  // conversion to nanoseconds in range.
  if (!(ms >= 0 && ms <= 86'400'000.0))
    throw ApiError(400, "duration_ms: " + dump(*it) + " is out of range (expected 0 to 86400000)");
  return link::Duration(static_cast<std::int64_t>(ms * 1e6));
}

std::size_t frames_limit(const ApiRequest& request) {
  std::size_t limit = 50;
  for (const auto& [key, value] : request.query) {
    if (key != "limit") continue;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), limit);
    if (ec != std::errc() || end != value.data() + value.size() || limit == 0 ||
        limit > kMaxFramesListed)
      throw ApiError(400, "limit: '" + value + "' is not a count from 1 to " +
                              std::to_string(kMaxFramesListed));
  }
  return limit;
}

bool is_json_content(const std::string& content_type) {
  std::string type = content_type.substr(0, content_type.find(';'));
  std::transform(type.begin(), type.end(), type.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  type.erase(0, type.find_first_not_of(' '));
  type.erase(type.find_last_not_of(' ') + 1);
  return type == "application/json" || type.ends_with("+json");
}

link::FaultProfile parse_faults_body(const ApiRequest& request) {
  const bool json_body = is_json_content(request.content_type);
  check_nesting(request.body, json_body);
  // JSON is YAML: a JSON body goes through the same reader, and its errors
  // give lines and columns of the body as sent.
  if (json_body) (void)parse_json_body(request);
  try {
    return link::parse_fault_profile_text(request.body, "body");
  } catch (const config::ConfigError& e) {
    throw ApiError(400, e.what());
  }
}

// ---- the endpoints ----

ApiReply get_version(Call& c) {
  ApiReply reply;
  reply.content_type = "text/plain; charset=utf-8";
  reply.body = "hil " + c.info.version + " (Toxiproxy API 2.x)";
  return reply;
}

ApiReply list_proxies(Call& c) {
  json proxies = json::object();
  for (const auto* route : c.hub.routes())
    proxies[route->spec.name] = to_json(*route);
  return json_reply(200, proxies);
}

ApiReply create_proxy(Call& c) {
  RouteSpec spec = parse_route_spec(parse_object_body(c.request));
  return json_reply(201, to_json(c.hub.create(std::move(spec))));
}

ApiReply populate(Call& c) {
  json body = parse_json_body(c.request);
  if (body.is_object() && body.contains("proxies")) body = body["proxies"];
  if (!body.is_array())
    throw ApiError(
        400, "body: expected an array of proxies ([{...}, ...]), got " + json_type_name(body));
  std::vector<RouteSpec> specs;
  for (std::size_t i = 0; i < body.size(); ++i) {
    try {
      if (!body[i].is_object())
        throw ApiError(400, "expected an object ({...}), got " + json_type_name(body[i]));
      specs.push_back(parse_route_spec(body[i]));
    } catch (const ApiError& e) {
      throw ApiError(e.status(), "[" + std::to_string(i) + "]." + e.what());
    }
  }
  json proxies = json::array();
  for (const auto* route : c.hub.populate(std::move(specs)))
    proxies.push_back(to_json(*route));
  return json_reply(201, {{"proxies", proxies}});
}

ApiReply get_proxy(Call& c) {
  return json_reply(200, to_json(c.hub.get(c.params[0])));
}

ApiReply update_proxy(Call& c) {
  const json body = parse_optional_object_body(c.request);
  c.hub.get(c.params[0]);  // 404 before any field is looked at
  auto listen = optional_string(body, "listen");
  auto upstream = optional_string(body, "upstream");
  auto enabled = optional_bool(body, "enabled");
  return json_reply(
      200, to_json(c.hub.update(c.params[0], std::move(listen), std::move(upstream), enabled)));
}

ApiReply delete_proxy(Call& c) {
  c.hub.remove(c.params[0]);
  return no_content();
}

ApiReply reset_all(Call& c) {
  c.hub.reset();
  return no_content();
}

ApiReply list_toxics(Call& c) {
  return json_reply(200, toxics_json(c.hub.get(c.params[0])));
}

ApiReply add_toxic(Call& c) {
  const json body = parse_object_body(c.request);
  c.hub.get(c.params[0]);
  return json_reply(200, to_json(c.hub.add_toxic(c.params[0], body)));
}

ApiReply get_toxic(Call& c) {
  return json_reply(200, to_json(c.hub.get_toxic(c.params[0], c.params[1])));
}

ApiReply update_toxic(Call& c) {
  const json body = parse_object_body(c.request);
  c.hub.get_toxic(c.params[0], c.params[1]);
  return json_reply(200, to_json(c.hub.update_toxic(c.params[0], c.params[1], body)));
}

ApiReply delete_toxic(Call& c) {
  c.hub.remove_toxic(c.params[0], c.params[1]);
  return no_content();
}

ApiReply all_links(Call& c) {
  json links = json::array();
  for (const auto* route : c.hub.routes()) {
    for (auto& link : route_links_json(*route))
      links.push_back(std::move(link));
  }
  return json_reply(200, links);
}

ApiReply route_links(Call& c) {
  return json_reply(200, route_links_json(c.hub.get(c.params[0])));
}

ApiReply get_faults(Call& c) {
  const auto& faults = c.hub.get(c.params[0]).spec.faults;
  return json_reply(200, {{"rules", faults.rules.size()}, {"yaml", fault_profile_yaml(faults)}});
}

ApiReply put_faults(Call& c) {
  c.hub.get(c.params[0]);
  link::FaultProfile faults = parse_faults_body(c.request);
  const std::size_t rules = faults.rules.size();
  c.hub.set_faults(c.params[0], std::move(faults));
  return json_reply(200, {{"rules", rules}});
}

ApiReply stall_link(Call& c) {
  c.hub.get(c.params[0]);
  const std::size_t number = link_number(c.params[1]);
  const json body = parse_object_body(c.request);
  const link::Duration duration = stall_duration(body);
  const link::DirectionFilter which = stall_direction(body);
  c.hub.stall_link(c.params[0], number, duration, which);
  return no_content();
}

ApiReply reset_link(Call& c) {
  c.hub.get(c.params[0]);
  c.hub.reset_link(c.params[0], link_number(c.params[1]));
  return no_content();
}

ApiReply recent_frames(Call& c) {
  const auto& route = c.hub.get(c.params[0]);
  const std::size_t limit = frames_limit(c.request);
  json frames = json::array();
  if (route.proxy) {
    for (const auto& f : route.proxy->recent_frames(limit)) {
      frames.push_back({{"link", f.link},
                        {"at_ms", link::to_ms(f.at)},
                        {"direction", link::to_string(f.direction)},
                        {"kind", f.frame.kind},
                        {"valid", f.frame.valid},
                        {"text", f.frame.text},
                        {"hex", protocol::to_hex(f.frame.raw)}});
    }
  }
  return json_reply(200, frames);
}

ApiReply metrics(Call& c) {
  ApiReply reply;
  reply.content_type = base::kPrometheusContentType;
  reply.body = base::prometheus_text(proxy_metrics(c.hub));
  return reply;
}

struct Endpoint {
  std::vector<std::string_view> pattern;  // "*" takes any one segment
  std::string_view method;
  ApiReply (*handle)(Call&);
};

const std::vector<Endpoint>& endpoints() {
  static const std::vector<Endpoint> table = {
      {{"version"}, "GET", get_version},
      {{"proxies"}, "GET", list_proxies},
      {{"proxies"}, "POST", create_proxy},
      {{"populate"}, "POST", populate},
      {{"reset"}, "POST", reset_all},
      {{"proxies", "*"}, "GET", get_proxy},
      {{"proxies", "*"}, "POST", update_proxy},
      {{"proxies", "*"}, "PATCH", update_proxy},
      {{"proxies", "*"}, "DELETE", delete_proxy},
      {{"proxies", "*", "toxics"}, "GET", list_toxics},
      {{"proxies", "*", "toxics"}, "POST", add_toxic},
      {{"proxies", "*", "toxics", "*"}, "GET", get_toxic},
      {{"proxies", "*", "toxics", "*"}, "POST", update_toxic},
      {{"proxies", "*", "toxics", "*"}, "PATCH", update_toxic},
      {{"proxies", "*", "toxics", "*"}, "DELETE", delete_toxic},
      {{"hil", "links"}, "GET", all_links},
      {{"hil", "proxies", "*", "links"}, "GET", route_links},
      {{"hil", "proxies", "*", "faults"}, "GET", get_faults},
      {{"hil", "proxies", "*", "faults"}, "PUT", put_faults},
      {{"hil", "proxies", "*", "links", "*", "stall"}, "POST", stall_link},
      {{"hil", "proxies", "*", "links", "*", "reset"}, "POST", reset_link},
      {{"hil", "proxies", "*", "frames"}, "GET", recent_frames},
      {{"metrics"}, "GET", metrics},
  };
  return table;
}

// The path's segments, each decoded; "/" alone has none, and one trailing
// '/' is ignored.
std::vector<std::string> path_segments(const std::string& path) {
  if (path.empty() || path[0] != '/')
    throw ApiError(400, "path: '" + path + "' does not start with '/'");
  std::string_view rest(path);
  rest.remove_prefix(1);
  if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
  std::vector<std::string> segments;
  if (rest.empty()) return segments;
  std::size_t start = 0;
  while (true) {
    const auto slash = rest.find('/', start);
    const auto raw = rest.substr(start, slash == std::string_view::npos ? slash : slash - start);
    auto decoded = percent_decode(raw);
    if (!decoded)
      throw ApiError(400,
                     "path: '" + std::string(raw) + "' has a '%' not followed by two hex digits");
    segments.push_back(std::move(*decoded));
    if (slash == std::string_view::npos) break;
    start = slash + 1;
  }
  return segments;
}

bool matches(const Endpoint& endpoint, const std::vector<std::string>& segments,
             std::vector<std::string>& params) {
  if (endpoint.pattern.size() != segments.size()) return false;
  params.clear();
  for (std::size_t i = 0; i < segments.size(); ++i) {
    if (endpoint.pattern[i] == "*") {
      if (segments[i].empty()) return false;
      params.push_back(segments[i]);
    } else if (endpoint.pattern[i] != segments[i]) {
      return false;
    }
  }
  return true;
}

ApiReply dispatch(ProxyHub& hub, const ApiRequest& request, const ApiInfo& info) {
  if (request.body.size() > kMaxApiBodyBytes)
    throw ApiError(413, "body: " + std::to_string(request.body.size()) +
                            " bytes is over the limit of " + std::to_string(kMaxApiBodyBytes));
  const std::vector<std::string> segments = path_segments(request.path);
  std::vector<std::string> params;
  std::vector<std::string> allowed;
  for (const Endpoint& endpoint : endpoints()) {
    if (!matches(endpoint, segments, params)) continue;
    if (endpoint.method == request.method) {
      Call call{hub, request, info, std::move(params)};
      return endpoint.handle(call);
    }
    allowed.emplace_back(endpoint.method);
  }
  if (allowed.empty())
    throw ApiError(404, "path: nothing at " + request.path + " (see docs/proxy-api.md)");
  std::string list;
  for (const auto& method : allowed)
    list += (list.empty() ? "" : ", ") + method;
  ApiReply reply = error_reply(405, "method: " + request.method + " is not allowed on " +
                                        request.path + " (allowed: " + list + ")");
  reply.headers.emplace_back("Allow", list);
  return reply;
}

// ---- a profile back as YAML ----

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

std::string duration_text(link::Duration d) {
  return duration_literal(d);
}

void emit_duration_range(YAML::Emitter& out, const char* key, const link::DurationRange& range) {
  out << YAML::Key << key;
  if (range.min == range.max) {
    out << YAML::Value << duration_text(range.min);
  } else {
    out << YAML::Value << YAML::Flow << YAML::BeginSeq << duration_text(range.min)
        << duration_text(range.max) << YAML::EndSeq;
  }
}

void emit_byte_range(YAML::Emitter& out, const char* key, const link::ByteCountRange& range) {
  out << YAML::Key << key;
  if (range.min == range.max) {
    out << YAML::Value << range.min;
  } else {
    out << YAML::Value << YAML::Flow << YAML::BeginSeq << range.min << range.max << YAML::EndSeq;
  }
}

void emit_action(YAML::Emitter& out, const link::FaultAction& action) {
  std::visit(
      Overloaded{
          [&](const link::Fragment& a) {
            emit_byte_range(out, "sizes", a.piece_bytes);
            if (a.gap != link::DurationRange{}) emit_duration_range(out, "gap", a.gap);
          },
          [&](const link::Coalesce& a) {
            if (a.count != 0) out << YAML::Key << "count" << YAML::Value << a.count;
            if (a.window != link::Duration{0})
              out << YAML::Key << "window" << YAML::Value << duration_text(a.window);
          },
          [&](const link::Corrupt& a) {
            out << YAML::Key << "target" << YAML::Value << std::string(link::to_string(a.target));
            if (!a.field.empty()) out << YAML::Key << "field" << YAML::Value << a.field;
            out << YAML::Key << "bits" << YAML::Value << a.bits;
          },
          [&](const link::Drop& a) {
            if (a.unit == link::DropUnit::bytes) {
              out << YAML::Key << "unit" << YAML::Value << "bytes";
              emit_byte_range(out, "count", a.count);
            }
          },
          [&](const link::Duplicate& a) {
            out << YAML::Key << "copies" << YAML::Value << a.copies;
          },
          [&](const link::Garbage& a) {
            if (a.fixed.empty()) {
              emit_byte_range(out, "length", a.length);
            } else {
              out << YAML::Key << "hex" << YAML::Value << protocol::to_hex(a.fixed);
            }
          },
          [&](const link::Delay& a) {
            out << YAML::Key << "delay" << YAML::Value << duration_text(a.base);
            if (a.jitter != link::Duration{0})
              out << YAML::Key << "jitter" << YAML::Value << duration_text(a.jitter);
          },
          [&](const link::Stall& a) {
            out << YAML::Key << "for" << YAML::Value << duration_text(a.duration);
          },
          [&](const link::Bandwidth& a) {
            out << YAML::Key << "bytes_per_second" << YAML::Value << a.bytes_per_second;
          },
          [&](const link::Refuse& a) {
            out << YAML::Key << "for" << YAML::Value << duration_text(a.duration);
          },
          [&](const link::LimitData& a) { out << YAML::Key << "bytes" << YAML::Value << a.bytes; },
          [&](const link::SlowClose& a) {
            out << YAML::Key << "delay" << YAML::Value << duration_text(a.delay);
          },
          [&](const link::Disconnect&) {},
          [&](const link::Reset&) {},
      },
      action);
}

void emit_trigger(YAML::Emitter& out, const link::Trigger& t) {
  if (!t.match.empty()) out << YAML::Key << "match" << YAML::Value << t.match;
  if (t.at_frame) out << YAML::Key << "at_frame" << YAML::Value << *t.at_frame;
  if (t.first) out << YAML::Key << "first" << YAML::Value << *t.first;
  if (t.every) out << YAML::Key << "every" << YAML::Value << *t.every;
  if (t.probability) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", *t.probability);
    out << YAML::Key << "probability" << YAML::Value << std::string(text);
  }
  if (t.at) out << YAML::Key << "at" << YAML::Value << duration_text(*t.at);
}

}  // namespace

ApiReply error_reply(int status, const std::string& message) {
  return json_reply(status, {{"error", message}, {"status", status}});
}

std::optional<std::string> percent_decode(std::string_view text) {
  const auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 2 >= text.size()) return std::nullopt;
    const int high = hex(text[i + 1]);
    const int low = hex(text[i + 2]);
    if (high < 0 || low < 0) return std::nullopt;
    out += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return out;
}

std::string fault_profile_yaml(const link::FaultProfile& profile) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "rules" << YAML::Value;
  if (profile.rules.empty()) {
    out << YAML::Flow << YAML::BeginSeq << YAML::EndSeq;
  } else {
    out << YAML::BeginSeq;
    for (const link::FaultRule& rule : profile.rules) {
      out << YAML::BeginMap;
      out << YAML::Key << "kind" << YAML::Value << std::string(link::to_string(rule.kind()));
      if (!rule.name.empty()) out << YAML::Key << "name" << YAML::Value << rule.name;
      if (rule.direction != link::DirectionFilter::both)
        out << YAML::Key << "direction" << YAML::Value
            << std::string(link::to_string(rule.direction));
      if (rule.window.from != link::Time{0})
        out << YAML::Key << "from" << YAML::Value << duration_text(rule.window.from);
      if (rule.window.to) out << YAML::Key << "to" << YAML::Value << duration_text(*rule.window.to);
      emit_trigger(out, rule.trigger);
      emit_action(out, rule.action);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

ApiReply handle_api_request(ProxyHub& hub, const ApiRequest& request, const ApiInfo& info) {
  try {
    return dispatch(hub, request, info);
  } catch (const ApiError& e) {
    return error_reply(e.status(), e.what());
  } catch (const config::ConfigError& e) {
    return error_reply(400, e.what());
  } catch (const std::bad_alloc&) {
    return error_reply(500, "internal error: out of memory");
  } catch (const std::exception& e) {
    return error_reply(500, std::string("internal error: ") + e.what());
  } catch (...) {
    return error_reply(500, "internal error: an unknown exception");
  }
}

}  // namespace hil::control

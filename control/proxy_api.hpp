#pragma once
// hil proxy's control API as a function: a request in, a reply out, no
// sockets. The Toxiproxy-compatible endpoints (/version, /proxies, ...,
// /populate, /reset), hil's own under /hil/, and /metrics; every path is in
// docs/proxy-api.md. Runs on the thread of the hub's executor.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "control/proxy_hub.hpp"
#include "link/faults/profile.hpp"

namespace hil::control {

struct ApiRequest {
  std::string method;  ///< "GET", "POST", "PUT", "PATCH", "DELETE"
  /// Without the query, still percent-encoded ("/proxies/my%2Fcar"): each
  /// segment is decoded on its own, so an encoded '/' stays in its name.
  std::string path;
  std::vector<std::pair<std::string, std::string>> query;  ///< decoded ?key=value pairs
  std::string content_type;  ///< the request's Content-Type, may be empty
  std::string body;
};

struct ApiReply {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;  ///< empty for 204
  /// Extra headers: Allow on a 405, Retry-After on a 429.
  std::vector<std::pair<std::string, std::string>> headers;
};

/// What the API says about the program serving it.
struct ApiInfo {
  std::string version = "0.0.0";  ///< GET /version: "hil VERSION (Toxiproxy API 2.x)"
};

/// A request body larger than this gets 413.
inline constexpr std::size_t kMaxApiBodyBytes = 256 * 1024;
/// JSON nested deeper than this (arrays and objects), or YAML flow
/// collections, is refused with 400 before it is parsed.
inline constexpr std::size_t kMaxBodyNesting = 64;
/// GET /hil/proxies/NAME/frames gives at most this many frames.
inline constexpr std::size_t kMaxFramesListed = 1000;

/// Answers one request. Never throws: a bad request is a 4xx whose body is
/// {"error": "FIELD: what was wrong (expected ...)", "status": N}; a 500
/// names what went wrong inside hil.
ApiReply handle_api_request(ProxyHub& hub, const ApiRequest& request, const ApiInfo& info = {});

/// The reply for an error, as every endpoint sends it.
ApiReply error_reply(int status, const std::string& message);

/// The profile as a YAML profile file that reads back to the same rules
/// (GET /hil/proxies/NAME/faults).
std::string fault_profile_yaml(const link::FaultProfile& profile);

/// Decodes %XX escapes; nullopt for a '%' not followed by two hex digits.
std::optional<std::string> percent_decode(std::string_view text);

}  // namespace hil::control

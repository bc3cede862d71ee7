#pragma once
// The one error of hil's control API: an HTTP status and a message that
// names the field at fault and what was expected, sent as Toxiproxy's
// clients expect it: {"error": MESSAGE, "status": STATUS}.

#include <stdexcept>
#include <string>

namespace hil::control {

class ApiError : public std::runtime_error {
 public:
  /// `message` reads "FIELD: what was wrong (expected ...)" where a field is
  /// at fault, e.g. "attributes.latency: -5 is negative (expected
  /// milliseconds, 0 or more)".
  ApiError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

}  // namespace hil::control

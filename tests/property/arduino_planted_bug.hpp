#pragma once
// Known bugs planted in the Arduino client on purpose, so the tests can show
// that they catch each one: an ArduinoClientCore that breaks one of the
// protocol's rules (its protected rule functions, overridden here). An
// ArduinoSession takes it as its core.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string_view>
#include <utility>

#include "client/arduino/core.hpp"

namespace hil::client::arduino::prop {

enum class PlantedBug : std::uint8_t {
  none,
  no_resend_on_bad_cs,  ///< NACK BAD_CS ends the request like any NACK, nothing resent
  any_seq_is_answer,    ///< a reply with another SEQ is taken for the request's answer
  fixed_timeout,        ///< every attempt waits base_timeout; the timeout never doubles
};

/// A planted bug and its name.
struct PlantedBugName {
  PlantedBug bug;
  std::string_view name;
};

/// Every planted bug with its name, `none` first: the one list that names
/// them, for whatever runs once per bug.
inline constexpr PlantedBugName kPlantedBugs[] = {
    {PlantedBug::none, "none"},
    {PlantedBug::no_resend_on_bad_cs, "no_resend_on_bad_cs"},
    {PlantedBug::any_seq_is_answer, "any_seq_is_answer"},
    {PlantedBug::fixed_timeout, "fixed_timeout"},
};
// In the enum's order, one entry per bug: a bug added to the enum must be
// added here (the last bug's value is the table's last index).
static_assert([] {
  for (std::size_t i = 0; i < std::size(kPlantedBugs); ++i) {
    if (static_cast<std::size_t>(kPlantedBugs[i].bug) != i) return false;
  }
  return std::size(kPlantedBugs) == static_cast<std::size_t>(PlantedBug::fixed_timeout) + 1;
}());

/// The Arduino client core with `bug` planted (none: the client as shipped).
class PlantedBugCore : public ArduinoClientCore {
 public:
  PlantedBugCore(PlantedBug bug, ClientConfig config)
      : ArduinoClientCore(std::move(config)), bug_(bug) {}

 protected:
  Duration timeout_of(int attempt) const override {
    return planted(PlantedBug::fixed_timeout) ? config().base_timeout
                                              : ArduinoClientCore::timeout_of(attempt);
  }
  bool answers(std::uint8_t request_seq, const protocol::arduino::Message& reply) const override {
    return planted(PlantedBug::any_seq_is_answer) || ArduinoClientCore::answers(request_seq, reply);
  }
  bool resend_on(const protocol::arduino::Nack& nack) const override {
    return !planted(PlantedBug::no_resend_on_bad_cs) && ArduinoClientCore::resend_on(nack);
  }

 private:
  bool planted(PlantedBug bug) const { return bug_ == bug; }

  PlantedBug bug_;
};

}  // namespace hil::client::arduino::prop

#pragma once
// Known bugs planted in the WR8 reference client (the document's dialect)
// on purpose, so the tests can show that they catch each one: a
// Wr8ClientCore that breaks one of the car's rules (its protected rule
// functions, overridden here). Each is a mistake real client teams make;
// tests/gate/clients/wr8_good.py `--bug` has the same three for an
// external client.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string_view>
#include <utility>

#include "client/wr8/core.hpp"

namespace hil::client::wr8::prop {

enum class PlantedBug : std::uint8_t {
  none,
  task_before_auth,    ///< logged in once AUTH is written: tasks go out before the AUTH-REPLY
  newest_task_answer,  ///< a RESPONSE answers the newest open request, whatever its COI
  no_backoff,          ///< reconnect at once after every failure or loss
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
    {PlantedBug::task_before_auth, "task_before_auth"},
    {PlantedBug::newest_task_answer, "newest_task_answer"},
    {PlantedBug::no_backoff, "no_backoff"},
};
// In the enum's order, one entry per bug: a bug added to the enum must be
// added here (the last bug's value is the table's last index).
static_assert([] {
  for (std::size_t i = 0; i < std::size(kPlantedBugs); ++i) {
    if (static_cast<std::size_t>(kPlantedBugs[i].bug) != i) return false;
  }
  return std::size(kPlantedBugs) == static_cast<std::size_t>(PlantedBug::no_backoff) + 1;
}());

/// The WR8 client core with `bug` planted (none: the client as shipped).
class PlantedBugCore : public Wr8ClientCore {
 public:
  PlantedBugCore(PlantedBug bug, ClientConfig config)
      : Wr8ClientCore(std::move(config)), bug_(bug) {}

 protected:
  bool login_awaits_reply() const override {
    return !planted(PlantedBug::task_before_auth) && Wr8ClientCore::login_awaits_reply();
  }
  std::uint8_t answered_coi(const proto::Response& r) const override {
    if (planted(PlantedBug::newest_task_answer)) {
      if (const auto newest = newest_open_coi()) return *newest;
    }
    return Wr8ClientCore::answered_coi(r);
  }
  Time reconnect_time(Time now, Duration delay) const override {
    return planted(PlantedBug::no_backoff) ? now : Wr8ClientCore::reconnect_time(now, delay);
  }

 private:
  bool planted(PlantedBug bug) const { return bug_ == bug; }

  PlantedBug bug_;
};

}  // namespace hil::client::wr8::prop

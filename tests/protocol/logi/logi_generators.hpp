#pragma once
// rapidcheck generators for LOGI messages.

#include <rapidcheck.h>

#include "protocol/logi/message.hpp"
#include "tests/protocol/arbitrary_support.hpp"

namespace rc {

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::logi::Direction, hil::protocol::logi::kAllDirections);

template <>
struct Arbitrary<hil::protocol::logi::Mode> {
  static Gen<hil::protocol::logi::Mode> arbitrary() {
    return gen::element(hil::protocol::logi::Mode::automatic, hil::protocol::logi::Mode::manual);
  }
};

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::logi::Command, hil::protocol::logi::kAllCommands);

template <>
struct Arbitrary<hil::protocol::logi::Status> {
  static Gen<hil::protocol::logi::Status> arbitrary() {
    using hil::protocol::logi::Status;
    // Extra keys: printable, free of the separators, and not a known key.
    const auto key = gen::suchThat(gen::nonEmpty(gen::container<std::string>(
                                       gen::oneOf(gen::inRange('A', 'Z'), gen::inRange('0', '9')))),
                                   [](const std::string& k) {
                                     for (const char* known : {"SP", "STA", "RUN", "MODE", "MAN",
                                                               "DIS", "TRK", "DEV", "OBS", "RPM"}) {
                                       if (k == known) return false;
                                     }
                                     return true;
                                   });
    const auto value = gen::container<std::string>(
        gen::suchThat(gen::inRange<char>(0x20, 0x7F), [](char c) { return c != ',' && c != '#'; }));
    const auto rpm = gen::inRange(-9999, 10000);
    return gen::build<Status>(
        gen::set(&Status::speed_percent, gen::inRange(0, 101)),
        gen::set(&Status::station, gen::inRange(0, 1000)), gen::set(&Status::running),
        gen::set(&Status::mode), gen::set(&Status::manual),
        gen::set(&Status::distance_cm, gen::inRange(0, 100000)),
        gen::set(&Status::track_mask, gen::inRange<std::uint8_t>(0, 16)),
        gen::set(&Status::deviation, gen::inRange(-1000, 1001)), gen::set(&Status::obstacle),
        gen::set(&Status::rpm, gen::construct<std::array<int, 4>>(rpm, rpm, rpm, rpm)),
        gen::set(&Status::extra,
                 gen::resize(4, gen::container<std::vector<std::pair<std::string, std::string>>>(
                                    gen::pair(key, value)))));
  }
};

template <>
struct Arbitrary<hil::protocol::logi::Message> {
  static Gen<hil::protocol::logi::Message> arbitrary() {
    namespace logi = hil::protocol::logi;
    using M = logi::Message;
    return gen::oneOf(
        gen::map(gen::inRange(0, 101), [](int v) { return M{logi::SetSpeed{v}}; }),
        gen::map(gen::arbitrary<bool>(), [](bool v) { return M{logi::SetRun{v}}; }),
        gen::map(gen::inRange(0, 1000), [](int v) { return M{logi::SetStation{v}}; }),
        gen::map(gen::arbitrary<logi::Mode>(), [](logi::Mode v) { return M{logi::SetMode{v}}; }),
        gen::map(gen::arbitrary<logi::Direction>(),
                 [](logi::Direction v) { return M{logi::Move{v}}; }),
        gen::map(gen::arbitrary<logi::Status>(), [](logi::Status v) { return M{std::move(v)}; }),
        gen::map(gen::pair(gen::arbitrary<logi::Command>(), gen::arbitrary<bool>()),
                 [](std::pair<logi::Command, bool> v) {
                   return M{logi::Feedback{v.first, v.second}};
                 }));
  }
};

}  // namespace rc

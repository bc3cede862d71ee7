#pragma once
// rapidcheck generators for Leka commands and command groups. Values stay
// within the ranges the default decoder accepts, and a group always fits
// the robot's 122-byte bound.

#include <rapidcheck.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "protocol/leka/codec.hpp"
#include "protocol/leka/message.hpp"
#include "tests/protocol/arbitrary_support.hpp"

namespace hil::test::leka {

/// Generates the command T from one generated value per field, in order.
template <class T, class... Fields>
rc::Gen<protocol::leka::Command> command_from(rc::Gen<Fields>... fields) {
  return rc::gen::apply([](Fields... v) { return protocol::leka::Command{T{v...}}; },
                        std::move(fields)...);
}

}  // namespace hil::test::leka

namespace rc {

HIL_ARBITRARY_FIELDS(hil::protocol::leka::Rgb, &hil::protocol::leka::Rgb::red,
                     &hil::protocol::leka::Rgb::green, &hil::protocol::leka::Rgb::blue);

template <>
struct Arbitrary<hil::protocol::leka::Command> {
  static Gen<hil::protocol::leka::Command> arbitrary() {
    namespace leka = hil::protocol::leka;
    using C = leka::Command;
    using Byte = std::uint8_t;
    using hil::test::leka::command_from;
    const auto spin = gen::inRange<Byte>(0, 2);
    const auto speed = gen::arbitrary<Byte>();
    const auto belt = gen::inRange<Byte>(0, 0x14);
    const auto rgb = gen::arbitrary<leka::Rgb>();
    return gen::oneOf(
        gen::just(C{leka::Info{}}), gen::just(C{leka::StopLed{}}), gen::just(C{leka::StopMotor{}}),
        gen::just(C{leka::StopRobot{}}),
        gen::map(rgb, [](leka::Rgb c) { return C{leka::EarAll{c}}; }),
        command_from<leka::EarSingle>(gen::inRange<Byte>(0, 2), rgb),
        gen::map(rgb, [](leka::Rgb c) { return C{leka::BeltAll{c}}; }),
        gen::apply(
            [](Byte a, Byte b, leka::Rgb c) {
              return C{leka::BeltRange{std::min(a, b), std::max(a, b), c}};
            },
            belt, belt, rgb),
        command_from<leka::BeltSingle>(belt, rgb), command_from<leka::MotorAll>(spin, speed),
        command_from<leka::MotorDuo>(spin, speed, spin, speed),
        command_from<leka::MotorLeft>(spin, speed), command_from<leka::MotorRight>(spin, speed),
        gen::map(gen::inRange<Byte>(0x51, 0x56), [](Byte id) { return C{leka::Motivator{id}}; }),
        gen::map(gen::inRange<Byte>(0x41, 0x50), [](Byte id) { return C{leka::Guidance{id}}; }));
  }
};

template <>
struct Arbitrary<hil::protocol::leka::CommandGroup> {
  static Gen<hil::protocol::leka::CommandGroup> arbitrary() {
    namespace leka = hil::protocol::leka;
    // Up to 40 commands, cut back to the first ones that fit 122 bytes.
    return gen::map(gen::nonEmpty(gen::resize(40, gen::container<std::vector<leka::Command>>(
                                                      gen::arbitrary<leka::Command>()))),
                    [](std::vector<leka::Command> commands) {
                      leka::CommandGroup g;
                      std::size_t bytes = 0;
                      for (auto& c : commands) {
                        const std::size_t size = 1 + leka::spec_of(c).data_bytes;
                        if (bytes + size > leka::kMaxGroupBytes) break;
                        bytes += size;
                        g.commands.push_back(std::move(c));
                      }
                      return g;
                    });
  }
};

}  // namespace rc

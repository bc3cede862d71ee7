#pragma once
// rapidcheck generators for Arduino serial robot messages.

#include <rapidcheck.h>

#include <string>

#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/message.hpp"
#include "tests/protocol/arbitrary_support.hpp"

namespace hil::test::arduino {

/// Text a CMD or PAYLOAD field may carry: printable ASCII without ^ $ * |,
/// short enough that any frame stays within the 256-byte receive guard.
inline rc::Gen<std::string> gen_field_text() {
  return rc::gen::resize(200, rc::gen::container<std::string>(rc::gen::suchThat(
                                  rc::gen::inRange<char>(0x20, 0x7F),
                                  [](char c) { return protocol::arduino::is_field_char(c); })));
}

}  // namespace hil::test::arduino

namespace rc {

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::arduino::NackCode, hil::protocol::arduino::kAllNackCodes);

template <>
struct Arbitrary<hil::protocol::arduino::Nack> {
  static Gen<hil::protocol::arduino::Nack> arbitrary() {
    namespace ard = hil::protocol::arduino;
    // Free text that spells a documented code decodes as that code, so the
    // text branch never produces one.
    const auto text = gen::suchThat(hil::test::arduino::gen_field_text(), [](const std::string& t) {
      return !ard::parse_nack_code(t).has_value();
    });
    return gen::oneOf(
        gen::map(gen::arbitrary<ard::NackCode>(), [](ard::NackCode c) { return ard::Nack{c}; }),
        gen::map(text, [](std::string t) { return ard::Nack{std::move(t)}; }));
  }
};

template <>
struct Arbitrary<hil::protocol::arduino::Body> {
  static Gen<hil::protocol::arduino::Body> arbitrary() {
    namespace ard = hil::protocol::arduino;
    using B = ard::Body;
    const auto signed_arg =
        gen::weightedOneOf<int>({{3, gen::inRange(-1000, 1001)},
                                 {1, gen::inRange(ard::kMinSignedArg, ard::kMaxSignedArg + 1)},
                                 {1, gen::element(ard::kMinSignedArg, ard::kMaxSignedArg, 0)}});
    return gen::oneOf(
        gen::just(B{ard::Ping{}}), gen::just(B{ard::StatusRequest{}}),
        gen::map(gen::inRange(0, ard::kMaxPwm + 1), [](int v) { return B{ard::SetSpeed{v}}; }),
        gen::map(signed_arg, [](int v) { return B{ard::Move{v}}; }),
        gen::map(signed_arg, [](int v) { return B{ard::Rotate{v}}; }), gen::just(B{ard::Stop{}}),
        gen::just(B{ard::SonarRead{}}), gen::just(B{ard::IrRead{}}), gen::just(B{ard::Help{}}),
        gen::map(hil::test::arduino::gen_field_text(),
                 [](std::string t) { return B{ard::Ack{std::move(t)}}; }),
        gen::map(gen::arbitrary<ard::Nack>(), [](ard::Nack n) { return B{std::move(n)}; }));
  }
};

HIL_ARBITRARY_FIELDS(hil::protocol::arduino::Message, &hil::protocol::arduino::Message::seq,
                     &hil::protocol::arduino::Message::body);

}  // namespace rc

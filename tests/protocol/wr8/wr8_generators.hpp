#pragma once
// rapidcheck generators for WR8 packets. Messages are valid under the
// default DATA table and parameter counts, in either byte order; tests that
// use the entries block unit clear Data::unparsed (it cannot travel there).

#include <rapidcheck.h>

#include "protocol/wr8/codec.hpp"
#include "tests/protocol/arbitrary_support.hpp"

namespace rc {

template <>
struct Arbitrary<hil::protocol::wr8::Word> {
  static Gen<hil::protocol::wr8::Word> arbitrary() {
    using hil::protocol::wr8::Word;
    // Plain numbers most of the time, any bit pattern (NaNs too) otherwise.
    return gen::oneOf(
        gen::map(gen::inRange(-100000, 100000), [](int v) { return Word::from_i32(v); }),
        gen::map(gen::inRange(-1000, 1000),
                 [](int v) { return Word::from_f32(static_cast<float>(v) / 8.0f); }),
        gen::map(gen::arbitrary<std::uint32_t>(), [](std::uint32_t v) { return Word{v}; }));
  }
};

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::wr8::State, hil::protocol::wr8::kAllStates);

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::wr8::SettingCode, hil::protocol::wr8::kAllSettingCodes);

HIL_ARBITRARY_ELEMENT_OF(hil::protocol::wr8::ResponseCode, hil::protocol::wr8::kAllResponseCodes);

template <>
struct Arbitrary<hil::protocol::wr8::Auth> {
  static Gen<hil::protocol::wr8::Auth> arbitrary() {
    using hil::protocol::wr8::Auth;
    return gen::map(
        gen::container<std::array<std::uint8_t, hil::protocol::wr8::kAuthTextBytes>>(
            gen::arbitrary<std::uint8_t>()),
        [](std::array<std::uint8_t, hil::protocol::wr8::kAuthTextBytes> t) { return Auth{t}; });
  }
};

HIL_ARBITRARY_FIELDS(hil::protocol::wr8::AuthReply, &hil::protocol::wr8::AuthReply::device_code,
                     &hil::protocol::wr8::AuthReply::device_id,
                     &hil::protocol::wr8::AuthReply::state);

template <>
struct Arbitrary<hil::protocol::wr8::Task> {
  static Gen<hil::protocol::wr8::Task> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    return gen::mapcat(gen::elementOf(wr8::kAllTaskCodes), [](wr8::TaskCode t) {
      const auto count = wr8::default_profile().task_parameter_count[static_cast<std::size_t>(t)];
      return gen::map(
          gen::pair(gen::arbitrary<std::uint8_t>(),
                    gen::container<std::vector<wr8::Word>>(count, gen::arbitrary<wr8::Word>())),
          [t](std::pair<std::uint8_t, std::vector<wr8::Word>> v) {
            return wr8::Task{v.first, t, std::move(v.second)};
          });
    });
  }
};

HIL_ARBITRARY_FIELDS(hil::protocol::wr8::Setting, &hil::protocol::wr8::Setting::code,
                     &hil::protocol::wr8::Setting::value);

template <>
struct Arbitrary<hil::protocol::wr8::Settings> {
  static Gen<hil::protocol::wr8::Settings> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    return gen::build<wr8::Settings>(
        gen::set(&wr8::Settings::coi),
        gen::set(&wr8::Settings::params, hil::test::up_to<wr8::Setting>(12)));
  }
};

HIL_ARBITRARY_FIELDS(hil::protocol::wr8::Response, &hil::protocol::wr8::Response::coi,
                     &hil::protocol::wr8::Response::code);

template <>
struct Arbitrary<hil::protocol::wr8::DataValue> {
  static Gen<hil::protocol::wr8::DataValue> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    return gen::oneOf(
        gen::map(gen::pair(gen::inRange<std::uint8_t>(0, 3), gen::arbitrary<wr8::Word>()),
                 [](std::pair<std::uint8_t, wr8::Word> v) {
                   return wr8::DataValue{v.first, v.second};
                 }),
        gen::map(gen::arbitrary<std::uint8_t>(), [](std::uint8_t b) {
          return wr8::DataValue{wr8::data_code::battery, wr8::Word{b}};
        }));
  }
};

template <>
struct Arbitrary<hil::protocol::wr8::Data> {
  static Gen<hil::protocol::wr8::Data> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    // At most 20 values (100 bytes) plus 30 unparsed bytes: within 255.
    const auto unparsed =
        gen::oneOf(gen::just(hil::protocol::Bytes{}),
                   gen::map(gen::pair(gen::inRange<std::uint8_t>(4, 255),
                                      gen::resize(29, gen::container<hil::protocol::Bytes>(
                                                          gen::arbitrary<std::uint8_t>()))),
                            [](std::pair<std::uint8_t, hil::protocol::Bytes> v) {
                              v.second.insert(v.second.begin(), v.first);
                              return v.second;
                            }));
    return gen::build<wr8::Data>(gen::set(&wr8::Data::state), gen::set(&wr8::Data::timestamp_ms),
                                 gen::set(&wr8::Data::values, hil::test::up_to<wr8::DataValue>(20)),
                                 gen::set(&wr8::Data::unparsed, unparsed));
  }
};

template <>
struct Arbitrary<hil::protocol::wr8::Message> {
  static Gen<hil::protocol::wr8::Message> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    using M = wr8::Message;
    return gen::oneOf(
        gen::just(M{wr8::Empty{}}), gen::cast<M>(gen::arbitrary<wr8::Auth>()),
        gen::cast<M>(gen::arbitrary<wr8::AuthReply>()), gen::cast<M>(gen::arbitrary<wr8::Task>()),
        gen::cast<M>(gen::arbitrary<wr8::Settings>()),
        gen::cast<M>(gen::arbitrary<wr8::Response>()), gen::cast<M>(gen::arbitrary<wr8::Data>()));
  }
};

/// Byte order and block unit; the tables stay the defaults.
template <>
struct Arbitrary<hil::protocol::wr8::Profile> {
  static Gen<hil::protocol::wr8::Profile> arbitrary() {
    namespace wr8 = hil::protocol::wr8;
    return gen::map(gen::pair(gen::element(wr8::ByteOrder::little, wr8::ByteOrder::big),
                              gen::element(wr8::BlockSizeUnit::bytes, wr8::BlockSizeUnit::entries)),
                    [](std::pair<wr8::ByteOrder, wr8::BlockSizeUnit> v) {
                      wr8::Profile p;
                      p.byte_order = v.first;
                      p.block_unit = v.second;
                      return p;
                    });
  }
};

}  // namespace rc

namespace hil::test {

/// The message as it can travel under `profile` (unparsed DATA bytes only
/// exist when sizes count bytes).
inline protocol::wr8::Message fit(protocol::wr8::Message m, const protocol::wr8::Profile& profile) {
  if (auto* d = std::get_if<protocol::wr8::Data>(&m);
      d != nullptr && profile.block_unit == protocol::wr8::BlockSizeUnit::entries) {
    d->unparsed.clear();
  }
  return m;
}

}  // namespace hil::test

// The RFC 2217 server codec, byte for byte: what a client sends, what the
// device gets, what goes back.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <initializer_list>

#include "link/rfc2217.hpp"

namespace hil::link {
namespace rfc2217_test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using Kind = Rfc2217Event::Kind;

constexpr std::uint8_t IAC = 255, SB = 250, SE = 240, WILL = 251, WONT = 252, DO = 253, DONT = 254;
constexpr std::uint8_t COM = 44, BINARY = 0, ECHO_OPT = 1, SGA = 3;

Bytes b(std::initializer_list<int> values) {
  Bytes out;
  for (const int v : values)
    out.push_back(static_cast<std::uint8_t>(v));
  return out;
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const auto& p : parts)
    out.insert(out.end(), p.begin(), p.end());
  return out;
}

/// IAC SB 44 <command> <value, 0xFF doubled> IAC SE
Bytes sb(std::uint8_t command, const Bytes& value = {}) {
  Bytes out = {IAC, SB, COM, command};
  for (const auto v : value) {
    out.push_back(v);
    if (v == IAC) out.push_back(IAC);
  }
  out.push_back(IAC);
  out.push_back(SE);
  return out;
}

Rfc2217Server make_server(std::uint32_t baud = 9600) {
  return Rfc2217Server(Rfc2217Server::Config{LineSettings{baud}, "hil", 0xB0});
}

std::vector<Kind> kinds(const std::vector<Rfc2217Event>& events) {
  std::vector<Kind> out;
  for (const auto& e : events)
    out.push_back(e.kind);
  return out;
}

std::string problems(const std::vector<Rfc2217Event>& events) {
  std::string text;
  for (const auto& e : events)
    if (e.kind == Kind::problem) text += e.text + "\n";
  return text;
}

TEST(Rfc2217Server, OpensByOfferingBinaryAndAskingForTheComPortOption) {
  auto server = make_server();
  server.open();
  EXPECT_EQ(server.take_to_client(),
            b({IAC, WILL, BINARY, IAC, DO, BINARY, IAC, WILL, SGA, IAC, DO, COM}));
}

TEST(Rfc2217Server, AnswersPySerialsOpeningNegotiation) {
  auto server = make_server();
  server.open();
  server.take_to_client();
  // What pySerial sends first: DO ECHO, WILL SGA, DO SGA, DO COM-PORT, WILL COM-PORT.
  server.receive(
      b({IAC, DO, ECHO_OPT, IAC, WILL, SGA, IAC, DO, SGA, IAC, DO, COM, IAC, WILL, COM}));
  // ECHO refused; SGA and COM-PORT already asked for by hil need no second
  // request; DO COM-PORT gets WILL; the modem lines follow the client's WILL.
  EXPECT_EQ(server.take_to_client(),
            cat({b({IAC, WONT, ECHO_OPT, IAC, DO, SGA, IAC, WILL, COM}), sb(107, {0xB0})}));
  EXPECT_THAT(kinds(server.take_events()), ElementsAre(Kind::com_port_on));
  EXPECT_TRUE(server.take_to_device().empty());
}

TEST(Rfc2217Server, RefusesOptionsItDoesNotOffer) {
  auto server = make_server();
  server.receive(b({IAC, WILL, 34, IAC, DO, 24}));  // LINEMODE, TERMINAL-TYPE
  EXPECT_EQ(server.take_to_client(), b({IAC, DONT, 34, IAC, WONT, 24}));
}

TEST(Rfc2217Server, SetBaudRateIsAnsweredWithTheRateInUse) {
  auto server = make_server();
  server.receive(sb(1, {0x00, 0x00, 0x4B, 0x00}));  // 19200
  EXPECT_EQ(server.take_to_client(), sb(101, {0x00, 0x00, 0x4B, 0x00}));
  EXPECT_EQ(server.settings().baud, 19200u);
  EXPECT_THAT(kinds(server.take_events()), ElementsAre(Kind::line_changed));
  // 0 asks for the rate in use, changes nothing.
  server.receive(sb(1, {0, 0, 0, 0}));
  EXPECT_EQ(server.take_to_client(), sb(101, {0x00, 0x00, 0x4B, 0x00}));
  EXPECT_TRUE(server.take_events().empty());
}

TEST(Rfc2217Server, AnAbsurdBaudRateIsRefusedWithTheRateInUse) {
  auto server = make_server(9600);
  server.receive(sb(1, {0x00, 0x3D, 0x09, 0x01}));  // 4,000,001
  EXPECT_EQ(server.take_to_client(), sb(101, {0x00, 0x00, 0x25, 0x80}));
  EXPECT_EQ(server.settings().baud, 9600u);
  EXPECT_THAT(problems(server.take_events()), HasSubstr("SET-BAUDRATE 4000001 refused"));
  server.receive(sb(1, {0xFF, 0xFF, 0xFF, 0xFF}));  // IAC doubled inside the value
  EXPECT_EQ(server.take_to_client(), sb(101, {0x00, 0x00, 0x25, 0x80}));
  EXPECT_THAT(problems(server.take_events()), HasSubstr("SET-BAUDRATE 4294967295 refused"));
}

TEST(Rfc2217Server, TheLargestRateIsTakenAndItsAnswerEscapesIac) {
  auto server = make_server();
  server.receive(sb(1, {0x00, 0x3D, 0x09, 0x00}));  // 4,000,000
  EXPECT_EQ(server.settings().baud, 4'000'000u);
  EXPECT_EQ(server.take_to_client(), sb(101, {0x00, 0x3D, 0x09, 0x00}));
  server.receive(sb(1, {0x00, 0x00, 0x00, 0xFF}));  // 255 baud: the answer doubles 0xFF
  EXPECT_EQ(server.take_to_client(), b({IAC, SB, COM, 101, 0, 0, 0, IAC, IAC, IAC, SE}));
}

TEST(Rfc2217Server, DataSizeParityAndStopSize) {
  auto server = make_server();
  server.receive(cat({sb(2, {7}), sb(3, {3}), sb(4, {2})}));
  EXPECT_EQ(server.take_to_client(), cat({sb(102, {7}), sb(103, {3}), sb(104, {2})}));
  EXPECT_EQ(server.settings(), (LineSettings{9600, 7, Parity::even, StopBits::two}));
  EXPECT_EQ(server.settings().describe(), "9600 baud 7E2");
  EXPECT_EQ(server.settings().half_bits_per_char(), 2u * (1 + 7 + 1 + 2));
  EXPECT_THAT(kinds(server.take_events()),
              ElementsAre(Kind::line_changed, Kind::line_changed, Kind::line_changed));
  // Queries (0) and refusals answer the setting in use.
  server.receive(cat({sb(2, {0}), sb(2, {9}), sb(3, {6}), sb(4, {3}), sb(4, {0})}));
  EXPECT_EQ(server.take_to_client(),
            cat({sb(102, {7}), sb(102, {7}), sb(103, {3}), sb(104, {3}), sb(104, {3})}));
  const auto events = server.take_events();
  EXPECT_THAT(problems(events), HasSubstr("SET-DATASIZE 9 refused"));
  EXPECT_THAT(problems(events), HasSubstr("SET-PARITY 6 refused"));
  EXPECT_EQ(server.settings().describe(), "9600 baud 7E1.5");
}

TEST(Rfc2217Server, SetControlSetsAndReportsTheLines) {
  auto server = make_server();
  EXPECT_TRUE(server.dtr());
  server.receive(cat({sb(5, {9}), sb(5, {12}), sb(5, {7}), sb(5, {10}), sb(5, {8})}));
  EXPECT_EQ(server.take_to_client(),
            cat({sb(105, {9}), sb(105, {12}), sb(105, {9}), sb(105, {12}), sb(105, {8})}));
  EXPECT_TRUE(server.dtr());
  EXPECT_FALSE(server.rts());
  const auto events = server.take_events();
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].kind, Kind::dtr);
  EXPECT_EQ(events[0].value, 0u);
  EXPECT_EQ(events[1].kind, Kind::rts);
  EXPECT_EQ(events[2].value, 1u);
}

TEST(Rfc2217Server, SetControlFlowControlAndBreak) {
  auto server = make_server();
  server.receive(cat({sb(5, {0}), sb(5, {3}), sb(5, {0}), sb(5, {13}), sb(5, {15}), sb(5, {13}),
                      sb(5, {5}), sb(5, {4}), sb(5, {6})}));
  EXPECT_EQ(server.take_to_client(),
            cat({sb(105, {1}), sb(105, {3}), sb(105, {3}), sb(105, {14}), sb(105, {15}),
                 sb(105, {15}), sb(105, {5}), sb(105, {5}), sb(105, {6})}));
  EXPECT_THAT(kinds(server.take_events()), ElementsAre(Kind::flow_control, Kind::flow_control,
                                                       Kind::break_state, Kind::break_state));
  server.receive(sb(5, {20}));
  EXPECT_TRUE(server.take_to_client().empty());
  EXPECT_THAT(problems(server.take_events()), HasSubstr("SET-CONTROL 20 is not a known setting"));
}

TEST(Rfc2217Server, PurgeMasksSignatureAndPolls) {
  auto server = make_server();
  server.receive(cat({sb(12, {1}), sb(12, {3}), sb(10, {0x10}), sb(11, {0x30}), sb(0), sb(7), sb(6),
                      sb(0, {'p', 'y'}), sb(8), sb(9)}));
  EXPECT_EQ(server.take_to_client(),
            cat({sb(112, {1}), sb(112, {3}), sb(110, {0x10}), sb(111, {0x30}),
                 sb(100, {'h', 'i', 'l'}), sb(107, {0xB0}), sb(106, {0})}));
  const auto events = server.take_events();
  EXPECT_THAT(kinds(events),
              ElementsAre(Kind::purge, Kind::purge, Kind::masks_changed, Kind::masks_changed,
                          Kind::signature, Kind::suspend, Kind::resume));
  EXPECT_EQ(events[1].value, 3u);
  EXPECT_EQ(events[3].value, 0x1030u);
  EXPECT_EQ(events[4].text, "py");
  // With the modem mask set, the notice after WILL COM-PORT is masked.
  server.receive(b({IAC, WILL, COM}));
  EXPECT_EQ(server.take_to_client(), cat({b({IAC, DO, COM}), sb(107, {0x30})}));
}

TEST(Rfc2217Server, DataPassesWithIacDoubledBothWays) {
  auto server = make_server();
  server.receive(b({'a', IAC, IAC, 'b', 0x00, 0x0D, 0x0A}));
  EXPECT_EQ(server.take_to_device(), b({'a', 0xFF, 'b', 0x00, 0x0D, 0x0A}));
  server.send_data(b({0xFF, 'x', 0xFF, 0xFF}));
  EXPECT_EQ(server.take_to_client(), b({IAC, IAC, 'x', IAC, IAC, IAC, IAC}));
}

TEST(Rfc2217Server, DataAroundCommandsStaysInOrder) {
  auto server = make_server();
  server.receive(cat({b({'^', '0'}), sb(1, {0, 0, 0x4B, 0}), b({'1', '$'})}));
  EXPECT_EQ(server.take_to_device(), b({'^', '0', '1', '$'}));
  EXPECT_EQ(server.settings().baud, 19200u);
}

// Everything a session may carry, split at every byte boundary, gives what
// it gives in one piece.
TEST(Rfc2217Server, EverySplitGivesTheSameResult) {
  const Bytes stream =
      cat({b({IAC, WILL, COM, IAC, DO, BINARY, 'h', IAC, IAC}), sb(1, {0, 0, 0xFF, 0xFF}), b({'i'}),
           sb(5, {8}), b({IAC, 241, 'j'}), sb(0, {'s', IAC}), sb(12, {3}), b({'k'})});
  auto whole = make_server();
  whole.receive(stream);
  const Bytes device = whole.take_to_device();
  const Bytes client = whole.take_to_client();
  const auto events = kinds(whole.take_events());
  EXPECT_EQ(device, b({'h', 0xFF, 'i', 'j', 'k'}));
  EXPECT_EQ(whole.settings().baud, 65535u);
  for (std::size_t cut = 1; cut < stream.size(); ++cut) {
    for (std::size_t cut2 = cut; cut2 < stream.size(); cut2 += 3) {
      auto split = make_server();
      const ByteView all(stream);
      split.receive(all.subspan(0, cut));
      split.receive(all.subspan(cut, cut2 - cut));
      split.receive(all.subspan(cut2));
      EXPECT_EQ(split.take_to_device(), device) << "cut at " << cut << " and " << cut2;
      EXPECT_EQ(split.take_to_client(), client) << "cut at " << cut << " and " << cut2;
      EXPECT_EQ(kinds(split.take_events()), events) << "cut at " << cut << " and " << cut2;
    }
  }
  // One byte at a time.
  auto bytewise = make_server();
  for (const auto byte : stream)
    bytewise.receive(ByteView(&byte, 1));
  EXPECT_EQ(bytewise.take_to_device(), device);
  EXPECT_EQ(bytewise.take_to_client(), client);
}

// Telnet commands inside a subnegotiation (IAC SB IAC IAC, IAC SB inside
// SB, IAC SE twice) break the grammar; whatever hil makes of them, the
// same bytes in other TCP segments give the device the same data (the
// fuzz target's finding, tests/fuzz/corpus/rfc2217/).
TEST(Rfc2217Server, CommandsInsideASubnegotiationGiveTheSameDataWhateverTheSegments) {
  const Bytes stream = b({IAC,  0xFA, IAC,  IAC,  0x5F, 0xE0, 0x00, 0x0B, 0xA7, 0x98, 0x03, 0x01,
                          IAC,  0xF0, IAC,  0x00, IAC,  0xFA, 0x2C, 0xF0, IAC,  0x05, ' ',  '1',
                          '6',  IAC,  0xFA, IAC,  IAC,  'd',  'a',  't',  0x04, 0x02, IAC,  0xF0,
                          0xF0, 0x08, IAC,  0xFA, 'V',  ',',  IAC,  0x05, ' ',  '1',  '6',  'x'});
  auto whole = make_server();
  whole.receive(stream);
  const Bytes device = whole.take_to_device();
  EXPECT_FALSE(problems(whole.take_events()).empty()) << "the broken grammar is logged";
  for (std::size_t cut = 1; cut < stream.size(); ++cut) {
    auto split = make_server();
    const ByteView all(stream);
    split.receive(all.subspan(0, cut));
    split.receive(all.subspan(cut));
    EXPECT_EQ(split.take_to_device(), device) << "cut at " << cut;
  }
}

TEST(Rfc2217Server, ShortOrLongValuesAreLoggedAndIgnored) {
  auto server = make_server();
  server.receive(cat({sb(1, {0, 0x4B}), sb(2), sb(5, {1, 2}), sb(12), sb(12, {4})}));
  EXPECT_TRUE(server.take_to_client().empty());
  EXPECT_TRUE(server.take_to_device().empty());
  EXPECT_EQ(server.settings().baud, 9600u);
  const std::string text = problems(server.take_events());
  EXPECT_THAT(text, HasSubstr("SET-BAUDRATE with 2 value byte(s), expected 4; ignored"));
  EXPECT_THAT(text, HasSubstr("SET-DATASIZE with 0 value byte(s), expected 1"));
  EXPECT_THAT(text, HasSubstr("SET-CONTROL with 2 value byte(s)"));
  EXPECT_THAT(text, HasSubstr("PURGE-DATA with 0 value byte(s)"));
  EXPECT_THAT(text, HasSubstr("PURGE-DATA 4 is not 1, 2 or 3"));
}

TEST(Rfc2217Server, UnknownCommandsAndOptionsAreLoggedAndIgnored) {
  auto server = make_server();
  server.receive(cat({sb(42, {1, 2, 3}), sb(101, {0, 0, 0, 1}), b({IAC, SB, 24, 1, IAC, SE}),
                      b({IAC, SB, COM, IAC, SE})}));
  EXPECT_TRUE(server.take_to_client().empty());
  EXPECT_TRUE(server.take_to_device().empty());
  const std::string text = problems(server.take_events());
  EXPECT_THAT(text, HasSubstr("unknown COM-PORT-OPTION command 42 (3 value byte(s))"));
  EXPECT_THAT(text, HasSubstr("unknown COM-PORT-OPTION command 101"));
  EXPECT_THAT(text, HasSubstr("subnegotiation of Telnet option 24 ignored"));
  EXPECT_THAT(text, HasSubstr("without a command"));
}

TEST(Rfc2217Server, ATruncatedSubnegotiationGivesNoDataByte) {
  auto server = make_server();
  // SET-BAUDRATE cut short by a new command: no IAC SE.
  server.receive(b({IAC, SB, COM, 1, 0, 0, IAC, WILL, COM, 'o', 'k'}));
  EXPECT_EQ(server.take_to_device(), b({'o', 'k'}));
  const auto events = server.take_events();
  EXPECT_THAT(problems(events), HasSubstr("SET-BAUDRATE with 2 value byte(s)"));
  EXPECT_THAT(problems(events), HasSubstr("Telnet: "));
  EXPECT_EQ(server.settings().baud, 9600u);
}

TEST(Rfc2217Server, AnEndlessSubnegotiationNeverTurnsIntoData) {
  auto server = make_server();
  Bytes junk = {IAC, SB, COM, 0};
  junk.resize(40'000, 'x');
  server.receive(junk);
  EXPECT_TRUE(server.take_to_device().empty());
  EXPECT_THAT(problems(server.take_events()), HasSubstr("Telnet: "));
  // Its end, then data again.
  server.receive(b({'x', 'x', IAC, SE, 'd'}));
  EXPECT_EQ(server.take_to_device(), b({'d'}));
}

// Random client bytes without 0xFF are all data; with 0xFF anywhere, the
// server never fails and never gives more data bytes than came in.
TEST(Rfc2217Server, RandomInput) {
  std::uint32_t seed = 12345;
  const auto next = [&seed] {
    seed = seed * 1664525U + 1013904223U;
    return static_cast<std::uint8_t>(seed >> 24);
  };
  for (int round = 0; round < 200; ++round) {
    Bytes plain;
    Bytes noisy;
    for (int i = 0; i < 300; ++i) {
      const std::uint8_t byte = next();
      plain.push_back(byte == IAC ? 'x' : byte);
      noisy.push_back(i % 7 == 0 ? IAC : byte);
    }
    auto clean = make_server();
    clean.receive(plain);
    EXPECT_EQ(clean.take_to_device(), plain);
    auto messy = make_server();
    messy.receive(noisy);
    messy.send_data(noisy);
    EXPECT_LE(messy.take_to_device().size(), noisy.size());
    messy.take_events();
    messy.take_to_client();
  }
}

TEST(Rfc2217Server, StrayTelnetCommandsAreNotData) {
  auto server = make_server();
  server.receive(b({'a', IAC, 241, 'b', IAC, 243, 'c', IAC, SE, 'd'}));  // NOP, BREAK, stray SE
  EXPECT_EQ(server.take_to_device(), b({'a', 'b', 'c', 'd'}));
  const std::string text = problems(server.take_events());
  EXPECT_THAT(text, HasSubstr("Telnet command 243 ignored"));
  EXPECT_THAT(text, HasSubstr("Telnet command 240 ignored"));
}

}  // namespace
}  // namespace rfc2217_test
}  // namespace hil::link

// The external-client contract's text side: the lines a program prints
// (results, events, anything else) and the placeholders of its command.

#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "harness/exec_client.hpp"

namespace hil::harness {
namespace {

TEST(ClientLines, OkAndFailAreResultsWithOrWithoutATimeStamp) {
  auto line = parse_client_line("ok speed 50");
  EXPECT_EQ(line.kind, ClientLine::Kind::result);
  EXPECT_TRUE(line.ok);

  line = parse_client_line("[   1.2340000] ok   speed 50");
  EXPECT_EQ(line.kind, ClientLine::Kind::result);
  EXPECT_TRUE(line.ok);

  line = parse_client_line("[   2.0000000] FAIL press FWD: Not in manual mode");
  EXPECT_EQ(line.kind, ClientLine::Kind::result);
  EXPECT_FALSE(line.ok);
  EXPECT_EQ(line.reason, "Not in manual mode");

  line = parse_client_line("fail no colon here");
  EXPECT_FALSE(line.ok);
  EXPECT_EQ(line.reason, "no colon here");

  line = parse_client_line("Fail");
  EXPECT_EQ(line.kind, ClientLine::Kind::result);
  EXPECT_EQ(line.reason, "the client reported a failure");
}

TEST(ClientLines, ResultWordsOnlyCountAsTheFirstWord) {
  EXPECT_EQ(parse_client_line("speed ok").kind, ClientLine::Kind::output);
  EXPECT_EQ(parse_client_line("okay then").kind, ClientLine::Kind::output);
  EXPECT_EQ(parse_client_line("failed to parse STAT").kind, ClientLine::Kind::output);
  EXPECT_EQ(parse_client_line("").kind, ClientLine::Kind::output);
  EXPECT_EQ(parse_client_line("[unclosed stamp ok").kind, ClientLine::Kind::output);
}

/// An event line and the client record it becomes: its kind, when the
/// case checks it, and the fields its data holds.
struct EventLine {
  const char* text;
  std::optional<RecordKind> kind;
  nlohmann::json data;
};

TEST(ClientLines, EventLinesBecomeTheReferenceClientsRecords) {
  const std::vector<EventLine> cases = {
      {"event connection connected", ClientKind::connection, {{"state", "connected"}}},
      {"[ 3.5] event command MV:FWD uncertain",
       ClientKind::command,
       {{"command", "MV:FWD"}, {"state", "uncertain"}}},
      {"event stale", ClientKind::stale, nlohmann::json::object()},
      {"event fresh", ClientKind::fresh, nlohmann::json::object()},
      {"event notice Not in manual mode", std::nullopt, {{"text", "Not in manual mode"}}},
      {"event parse_error bad_checksum: checksum 00, computed 4D",
       ClientKind::parse_error,
       {{"text", "bad_checksum: checksum 00, computed 4D"}}},
      {"event movement disabled not connected",
       ClientKind::movement,
       {{"enabled", false}, {"reason", "not connected"}}},
      {"event movement enabled", std::nullopt, {{"enabled", true}}},
      {"event login failed wrong key", std::nullopt, {{"ok", false}, {"reason", "wrong key"}}},
  };
  for (const EventLine& c : cases) {
    SCOPED_TRACE(c.text);
    const auto line = parse_client_line(c.text);
    ASSERT_EQ(line.kind, ClientLine::Kind::event);
    if (c.kind) EXPECT_EQ(line.record_kind, *c.kind);
    for (const auto& [field, value] : c.data.items())
      EXPECT_EQ(line.record_data[field], value) << field;
  }
}

TEST(ClientLines, MalformedEventsAreKeptAsOutputNotGuessed) {
  for (const char* text : {"event", "event connection", "event connection flying",
                           "event connection connected now", "event command SP", "event stale now",
                           "event notice", "event login maybe", "event party"}) {
    EXPECT_EQ(parse_client_line(text).kind, ClientLine::Kind::output) << text;
  }
}

TEST(Placeholders, AreReplacedByShellQuotedValues) {
  const Placeholders values{{"host", "127.0.0.1"}, {"port", "40001"}, {"actions", "/tmp/a b/it's"}};
  EXPECT_EQ(substitute_placeholders("client --host {host} --port {port}", values),
            "client --host '127.0.0.1' --port '40001'");
  EXPECT_EQ(substitute_placeholders("run {actions}", values), R"(run '/tmp/a b/it'\''s')");
  EXPECT_EQ(substitute_placeholders("no placeholders", values), "no placeholders");
}

TEST(Placeholders, BracesThatAreNotPlaceholdersStayAsWritten) {
  const Placeholders values{{"port", "1"}};
  EXPECT_EQ(substitute_placeholders("jq '{}' {port} {A} {a-b} {", values),
            "jq '{}' '1' {A} {a-b} {");
}

// The std::invalid_argument substitute_placeholders() throws, or "accepted".
std::string substitution_error(std::string_view command, const Placeholders& values) {
  try {
    substitute_placeholders(command, values);
    return "accepted";
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

TEST(Placeholders, AnUnknownOneIsAnErrorWithItsColumn) {
  EXPECT_EQ(substitution_error("client {hots}", {{"host", "h"}}),
            "column 8: unknown placeholder '{hots}' (known: {host}, {port}, {endpoint}, "
            "{pty}, {actions}, {scenario}, {profile})");
}

TEST(Placeholders, OneWithoutAValueForThisCarSaysWhatToUse) {
  EXPECT_EQ(substitution_error("client {pty}", {{"host", "h"}, {"port", "1"}}),
            "column 8: '{pty}' has no value for this car (it talks TCP: use "
            "{host} and {port})");
}

TEST(ShellQuote, KeepsAnyTextOneWord) {
  EXPECT_EQ(shell_quote(""), "''");
  EXPECT_EQ(shell_quote("a b"), "'a b'");
  EXPECT_EQ(shell_quote("$(rm -rf /)"), "'$(rm -rf /)'");
  EXPECT_EQ(shell_quote("'"), R"(''\''')");
}

}  // namespace
}  // namespace hil::harness

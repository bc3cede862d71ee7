// The external-client contract's text side: the lines a program prints
// (results, events, anything else) and the placeholders of its command.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <string_view>

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

TEST(ClientLines, EventLinesBecomeTheReferenceClientsRecords) {
  auto line = parse_client_line("event connection connected");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_kind, ClientKind::connection);
  EXPECT_EQ(line.record_data["state"], "connected");

  line = parse_client_line("[ 3.5] event command MV:FWD uncertain");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_kind, ClientKind::command);
  EXPECT_EQ(line.record_data["command"], "MV:FWD");
  EXPECT_EQ(line.record_data["state"], "uncertain");

  line = parse_client_line("event stale");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_kind, ClientKind::stale);
  EXPECT_EQ(parse_client_line("event fresh").record_kind, ClientKind::fresh);

  line = parse_client_line("event notice Not in manual mode");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_data["text"], "Not in manual mode");

  line = parse_client_line("event parse_error bad_checksum: checksum 00, computed 4D");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_kind, ClientKind::parse_error);
  EXPECT_EQ(line.record_data["text"], "bad_checksum: checksum 00, computed 4D");

  line = parse_client_line("event movement disabled not connected");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_kind, ClientKind::movement);
  EXPECT_EQ(line.record_data["enabled"], false);
  EXPECT_EQ(line.record_data["reason"], "not connected");
  EXPECT_EQ(parse_client_line("event movement enabled").record_data["enabled"], true);

  line = parse_client_line("event login failed wrong key");
  ASSERT_EQ(line.kind, ClientLine::Kind::event);
  EXPECT_EQ(line.record_data["ok"], false);
  EXPECT_EQ(line.record_data["reason"], "wrong key");
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

// The Arduino client's frame log: UTC ISO-8601 times with Z, the raw text,
// its hex and the SEQ, exported as txt, csv and ndjson, safe from many threads.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "client/arduino/comm_log.hpp"

namespace hil::client::arduino {
namespace {

// 2026-11-22T06:07:51.123456Z in microseconds since the epoch.
constexpr std::int64_t kT = 1'795'327'671'123'456;

void add_two_frames(CommLog& log) {
  log.add({LogKind::tx, kT, "^01|PING|*11$", 0x01});
  log.add({LogKind::rx, kT + 15'000, "^01|ACK|OK*4C$", 0x01});
}

std::string two_frames_as(LogFormat format) {
  CommLog log;
  add_two_frames(log);
  return log.to_string(format);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

TEST(ArduinoCommLog, TimesAreUtcIso8601WithZ) {
  EXPECT_EQ(iso8601_utc(kT), "2026-11-22T06:07:51.123Z");
  EXPECT_EQ(iso8601_utc(0), "1970-01-01T00:00:00.000Z");
}

TEST(ArduinoCommLog, TextHasOneLinePerFrameWithDirectionSeqRawAndHex) {
  const auto out = lines(two_frames_as(LogFormat::txt));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0],
            "2026-11-22T06:07:51.123Z TX seq=01 ^01|PING|*11$ [5E 30 31 7C 50 49 4E 47 7C 2A "
            "31 31 24]");
  EXPECT_EQ(out[1].rfind("2026-11-22T06:07:51.138Z RX seq=01 ^01|ACK|OK*4C$ [", 0), 0u) << out[1];
}

TEST(ArduinoCommLog, CsvHasAHeaderAndQuotesFieldsThatNeedIt) {
  CommLog log;
  add_two_frames(log);
  log.add({LogKind::rx, kT, "^02|ACK|a,\"b\"*00$", std::nullopt});
  const auto out = lines(log.to_string(LogFormat::csv));
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0], "time,direction,seq,raw,hex");
  EXPECT_EQ(out[1].rfind("2026-11-22T06:07:51.123Z,TX,01,^01|PING|*11$,5E 30 31", 0), 0u) << out[1];
  EXPECT_EQ(out[3].rfind("2026-11-22T06:07:51.123Z,RX,,\"^02|ACK|a,\"\"b\"\"*00$\",", 0), 0u)
      << out[3];
}

TEST(ArduinoCommLog, NdjsonIsOneObjectPerLine) {
  const auto out = lines(two_frames_as(LogFormat::ndjson));
  ASSERT_EQ(out.size(), 2u);
  const auto j = nlohmann::json::parse(out[1]);
  EXPECT_EQ(j["time"], "2026-11-22T06:07:51.138Z");
  EXPECT_EQ(j["direction"], "RX");
  EXPECT_EQ(j["raw"], "^01|ACK|OK*4C$");
  EXPECT_EQ(j["seq"], 1);
  EXPECT_EQ(j["hex"], "5E 30 31 7C 41 43 4B 7C 4F 4B 2A 34 43 24");
}

TEST(ArduinoCommLog, SaveWritesTheFormatTheFileNameAsksFor) {
  EXPECT_EQ(log_format_for("logs.csv"), LogFormat::csv);
  EXPECT_EQ(log_format_for("logs.json"), LogFormat::ndjson);
  EXPECT_EQ(log_format_for("logs.txt"), LogFormat::txt);
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-arduino-log-" + std::to_string(::getpid()) + ".csv");
  CommLog log;
  add_two_frames(log);
  ASSERT_TRUE(log.save(path.string(), log_format_for(path.string())));
  std::ifstream in(path);
  std::stringstream content;
  content << in.rdbuf();
  EXPECT_EQ(content.str(), log.to_string(LogFormat::csv));
  std::filesystem::remove(path);
  EXPECT_FALSE(log.save("/nonexistent-dir/x.txt", LogFormat::txt));
}

TEST(ArduinoCommLog, ManyThreadsLoggingAtOnceLoseNothing) {
  CommLog log;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&log, t] {
      for (int i = 0; i < 1000; ++i) {
        log.add({LogKind::tx, kT + i, "^00|PING|*10$", static_cast<std::uint8_t>(t)});
        if (i % 100 == 0) (void)log.to_string(LogFormat::txt);
      }
    });
  }
  for (auto& th : threads)
    th.join();
  EXPECT_EQ(log.size(), 4000u);
  EXPECT_EQ(lines(log.to_string(LogFormat::ndjson)).size(), 4000u);
}

}  // namespace
}  // namespace hil::client::arduino

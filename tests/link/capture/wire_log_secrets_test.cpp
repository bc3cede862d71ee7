// The wire log keeps every byte (the capture) but its decoded frame texts,
// which people read, never show a WR8 authentication string.

#include <gtest/gtest.h>

#include "link/capture/wire_log.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/profile.hpp"
#include "tests/link/capture/capture_support.hpp"

namespace hil::link {
namespace {

namespace wr8 = protocol::wr8;

wr8::Auth auth_of(std::string_view s) {
  wr8::Auth auth;
  std::copy(s.begin(), s.end(), auth.text.begin());
  return auth;
}

TEST(WireLogSecrets, AuthFrameTextsAreMaskedButTheBytesAreAllThere) {
  test::ScratchFile file(".ndjson");
  std::error_code ec;
  auto log = WireLog::open(file.path(), WireLogOptions{"car0", protocol_adapter("wr8"), {}}, ec);
  ASSERT_TRUE(log) << ec.message();
  const auto right = wr8::encode(wr8::Auth{wr8::default_profile().auth_text});
  const auto wrong = wr8::encode(auth_of("GUESS-4242"));
  log->on_sent(milliseconds(1), Direction::to_car, right);
  log->on_delivered(milliseconds(2), Direction::to_car, wrong);
  log.reset();

  const auto contents = file.contents();
  EXPECT_EQ(contents.find("HIL-WR8-01"), std::string::npos) << contents;
  EXPECT_EQ(contents.find("GUESS-4242"), std::string::npos) << contents;
  const auto r = read_wire_log(file.path());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0]["frames"][0]["kind"], "AUTH");
  EXPECT_EQ(r[0]["frames"][0]["text"], "Auth text=********** (profile string)");
  EXPECT_EQ(r[1]["frames"][0]["text"], "Auth text=**********");
  // The capture itself is complete: every byte, in hex.
  EXPECT_EQ(bytes_of(r[0]), right);
  EXPECT_EQ(bytes_of(r[1]), wrong);
}

TEST(WireLogSecrets, OnlyAuthTextsAreMasked) {
  EXPECT_EQ(masked_frame_text("TASK", "Task coi=1 check"), "Task coi=1 check");
  EXPECT_EQ(masked_frame_text("AUTH", R"(Auth text="a\"b" (profile string))"),
            "Auth text=********** (profile string)");
  EXPECT_EQ(masked_frame_text("AUTH", "odd text"), "Auth text=**********");
  EXPECT_EQ(masked_frame_text("AUTH", ""), "");
  // Masking what is masked changes nothing.
  EXPECT_EQ(masked_frame_text("AUTH", "Auth text=********** (profile string)"),
            "Auth text=********** (profile string)");
  EXPECT_EQ(masked_frame_text("AUTH", "Auth text=**********"), "Auth text=**********");
}

}  // namespace
}  // namespace hil::link

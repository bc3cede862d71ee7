// The protocol calculator as QA uses it: examples from the README and the
// protocol documents, and the errors a mistyped command gets.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::test {
namespace {

using ::testing::HasSubstr;
using namespace std::string_literals;

/// `hil profiles` text with its folded lines joined again: every line end
/// and the indent after it become one space.
std::string unfolded(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n') {
      out += text[i];
      continue;
    }
    while (i + 1 < text.size() && text[i + 1] == ' ')
      ++i;
    out += ' ';
  }
  return out;
}

TEST(HilCli, EncodesLogiFromPayload) {
  const auto r = run_hil("encode logi SP:050");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "LOGI:SP:050:D7#\n");
}

TEST(HilCli, EncodesLogiStatus) {
  const auto r = run_hil(
      "encode logi "
      "STAT:SP:050,STA:002,RUN:1,MODE:AUTO,MAN:STOP,DIS:123,TRK:0110,DEV:-3,OBS:0,RPM:1:2:3:4");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("LOGI:STAT:SP:050,STA:002"));
}

TEST(HilCli, RefusesAnInvalidLogiPayloadAndSaysWhy) {
  const auto r = run_hil("encode logi SP:101");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("speed percent 000..100"));
  EXPECT_THAT(r.output, HasSubstr("--raw"));
}

TEST(HilCli, RawFramesAnyLogiPayload) {
  const auto r = run_hil("encode logi --raw SP:5");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "LOGI:SP:5:77#\n");
}

TEST(HilCli, DecodesLogiFramesAndReportsErrors) {
  const auto ok = run_hil("decode logi 'LOGI:SP:050:D7#'");
  EXPECT_EQ(ok.exit_code, 0);
  EXPECT_THAT(ok.output, HasSubstr("SetSpeed percent=50"));

  const auto bad = run_hil("decode logi 'LOGI:SP:050:D8#'");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output, HasSubstr("bad_checksum: checksum D8, computed D7"));
  EXPECT_THAT(bad.output, HasSubstr("raw: LOGI:SP:050:D8#"));
}

TEST(HilCli, LenientLogiDecodeToleratesLowercaseChecksum) {
  const auto strict = run_hil("decode logi 'LOGI:SP:050:d7#'");
  EXPECT_EQ(strict.exit_code, 1);
  EXPECT_THAT(strict.output, HasSubstr("lowercase_checksum"));
  const auto lenient = run_hil("decode logi --lenient 'LOGI:SP:050:d7#'");
  EXPECT_EQ(lenient.exit_code, 0);
  EXPECT_THAT(lenient.output, HasSubstr("tolerated: lowercase_checksum"));
}

TEST(HilCli, DecodesAStreamFromAFileWithSummary) {
  const auto r =
      run_hil("decode logi --no-raw --summary --file scenarios/captures/logi-session.txt");
  EXPECT_EQ(r.exit_code, 1);  // the capture holds deliberate errors
  EXPECT_THAT(r.output, HasSubstr("summary: 739 bytes, 13 frame(s), 4 error(s)"));
}

TEST(HilCli, DecodesHexInput) {
  const auto r = run_hil("decode logi --hex '4C 4F 47 49 3A 53 50 3A 30 35 30 3A 44 37 23'");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("SetSpeed percent=50"));
}

TEST(HilCli, MalformedCommandLinesExitTwoWithAMessage) {
  const auto missing = run_hil("encode logi");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("payload is required"));

  const auto unknown = run_hil("encode nosuchcar X");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output, HasSubstr("nosuchcar"));
}

TEST(HilCli, UnreadableInputExitsOneWithAMessage) {
  const auto no_file = run_hil("decode logi --file /nonexistent/capture");
  EXPECT_EQ(no_file.exit_code, 1);
  EXPECT_THAT(no_file.output, HasSubstr("cannot open '/nonexistent/capture'"));

  const auto bad_hex = run_hil("decode logi --hex 'GG'");
  EXPECT_EQ(bad_hex.exit_code, 1);
  EXPECT_THAT(bad_hex.output, HasSubstr("is not hex bytes"));

  const auto nothing = run_hil("decode logi");
  EXPECT_EQ(nothing.exit_code, 1);
  EXPECT_THAT(nothing.output, HasSubstr("no bytes to decode"));
}

TEST(HilCli, EncodesArduinoWithSequenceNumber) {
  const auto r = run_hil("encode arduino --seq 2 V 160");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "^02|V|160*63$\n");
  EXPECT_EQ(run_hil("encode arduino --seq 4 R -90").output, "^04|R|-90*72$\n");
  // The real sketch (the default) wants one space where there is no argument.
  EXPECT_EQ(run_hil("encode arduino --seq 8 STATUS").output, "^08|STATUS| *3C$\n");
  EXPECT_EQ(run_hil("encode arduino --profile readme --seq 8 STATUS").output, "^08|STATUS|*1C$\n");
  EXPECT_EQ(run_hil("encode arduino --seq 2 V:160").output, "^02|V|160*63$\n");
}

TEST(HilCli, RefusesArduinoSpeedOutOfRange) {
  const auto r = run_hil("encode arduino --seq 2 V 300");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("0..255"));
}

TEST(HilCli, DecodesArduinoRequest) {
  const auto r = run_hil("decode arduino --profile readme '^02|V|160*63$'");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("SetSpeed seq=02 pwm=160"));
  // The real sketch's view (the default profile): a request it acts on,
  // typed.
  const auto sketch = run_hil("decode arduino '^02|V|160*63$'");
  EXPECT_EQ(sketch.exit_code, 0);
  EXPECT_EQ(sketch.output, "request SetSpeed seq=02 pwm=160  ^02|V|160*63$\n");
}

TEST(HilCli, EncodesLekaFramesAsSpacedHex) {
  EXPECT_EQ(run_hil("encode leka info").output, "2A 2B 2C 2D 01 70 70\n");
  EXPECT_EQ(run_hil("encode leka led.belt.single 0 255 0 0").output,
            "2A 2B 2C 2D 05 15 00 FF 00 00 41\n");
  const auto group = run_hil("encode leka led.ear.all 255 0 0 + motor.all 1 200");
  EXPECT_EQ(group.exit_code, 0);
  EXPECT_THAT(group.output, HasSubstr("2A 2B 2C 2D 07 11 FF 00 00 21 01 C8"));
}

TEST(HilCli, DecodesLekaFrame) {
  const auto r = run_hil("decode leka 2A 2B 2C 2D 05 15 00 FF 00 00 41");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("led.belt.single"));
  const auto bad = run_hil("decode leka 2A 2B 2C 2D 05 15 00 FF 00 00 42");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output, HasSubstr("bad_checksum"));
}

TEST(HilCli, EncodesAndDecodesWr8) {
  EXPECT_EQ(run_hil("encode wr8 task 1 drive 100").output, "03 01 01 04 64 00 00 00\n");
  EXPECT_EQ(run_hil("encode wr8 response 1 completed").output, "05 01 02\n");
  const auto r = run_hil("decode wr8 03 01 01 04 64 00 00 00");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("Task"));
  EXPECT_THAT(r.output, HasSubstr("100"));
}

// The real WR8 programs (smart_vehicle_gui 8d80e92 and 431e8d4) put a
// length byte before every packet: hil encode prints it first, hil decode
// reads by it.
TEST(HilCli, EncodesEveryPacketOfSvgui2019WithItsLengthByte) {
  const auto encode = [](const std::string& form) {
    const auto r = run_hil("encode wr8 --profile svgui-2019 " + form);
    EXPECT_EQ(r.exit_code, 0) << form << ": " << r.output;
    return r.output;
  };
  EXPECT_EQ(encode("auth"), "0B 01 6B 6F 6E 6E 69 63 68 69 77 61\n");  // 0B 01 konnichiwa
  EXPECT_EQ(encode("auth-reply"), "04 02 01 02 03\n");
  EXPECT_EQ(encode("auth-reply 1 2 run"), "04 02 01 02 01\n");
  EXPECT_EQ(encode("task 7 forward 100"), "08 03 07 01 01 64 00 00 00\n");
  EXPECT_EQ(encode("task 1 wheels -15"), "08 03 01 02 01 F1 FF FF FF\n");
  EXPECT_EQ(encode("task 3 turn-signals"), "04 03 03 03 00\n");
  EXPECT_EQ(encode("task 2 4"), "04 03 02 04 00\n");  // a type the vehicle ignores
  EXPECT_EQ(encode("settings 5 3 1 90 100"),
            "12 04 05 03 00 00 00 01 00 00 00 5A 00 00 00 64 00 00 00\n");
  EXPECT_EQ(encode("answer 7 done"), "03 05 07 02\n");
  EXPECT_EQ(encode("answer 7 0"), "03 05 07 00\n");
  // 42 bytes after the length byte, big-endian, 4-byte codes before values.
  EXPECT_EQ(encode("data run 36000000 encoder=120 steering=1.5 motor-battery=87 "
                   "computer-battery=95"),
            "2A 06 01 02 25 51 00 00 00 00 01 00 00 00 78 00 00 00 02 3F F8 00 00 00 00 00 00 00 "
            "00 00 03 00 00 00 57 00 00 00 04 00 00 00 5F\n");
  EXPECT_EQ(encode("packet 9 01 02"), "03 09 01 02\n");
}

TEST(HilCli, EncodesEveryPacketOfSvguiHeadWithItsLengthByte) {
  const auto encode = [](const std::string& form) {
    const auto r = run_hil("encode wr8 --profile svgui-head " + form);
    EXPECT_EQ(r.exit_code, 0) << form << ": " << r.output;
    return r.output;
  };
  EXPECT_EQ(encode("auth"), "0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00\n");  // and the NUL
  EXPECT_EQ(encode("auth --text-hex 6B6F"), "03 01 6B 6F\n");
  EXPECT_EQ(encode("auth-reply"), "04 02 01 02 03\n");
  const std::string zero = " 00 00 00 00 00 00 00 00";
  std::string set = "61 04 3F F8 00 00 00 00 00 00";  // steering-p 1.5
  for (int i = 1; i < 7; ++i)
    set += zero;
  set += " 40 59 00 00 00 00 00 00";  // forward-int 100
  for (int i = 8; i < 12; ++i)
    set += zero;
  EXPECT_EQ(encode("set steering-p=1.5 forward-int=100"), set + "\n");
  EXPECT_EQ(encode("answer applied"), "02 05 01\n");
  EXPECT_EQ(encode("answer 0"), "02 05 00\n");
  EXPECT_EQ(encode("set-request"), "01 06\n");
  EXPECT_EQ(encode("map 01100000 00000000"),
            "1F 07 08 02 00 00 00 02 00 00 00 08 00 01 01 00 00 00 00 00 00 00 00 08 00 00 00 00 "
            "00 00 00 00\n");
  EXPECT_EQ(encode("map 1,-1 0,127"),
            "13 07 02 02 00 00 00 02 00 00 00 02 01 FF 00 00 00 02 00 7F\n");
  EXPECT_EQ(encode("low-freq-data wait 36000000 motor-battery=87 computer-battery=95 "
                   "temperature=41.5"),
            "22 08 03 02 25 51 00 00 00 00 01 00 00 00 57 00 00 00 02 00 00 00 5F 00 00 00 03 40 "
            "44 C0 00 00 00 00 00\n");
  EXPECT_EQ(encode("high-freq-data 36000000 encoder=1.5 steering=-10 x=0.25 y=0.5 angle=90"),
            "41 09 02 25 51 00 00 00 00 01 3F F8 00 00 00 00 00 00 00 00 00 02 C0 24 00 00 00 00 "
            "00 00 00 00 00 03 3F D0 00 00 00 00 00 00 00 00 00 04 3F E0 00 00 00 00 00 00 00 00 "
            "00 05 40 56 80 00 00 00 00 00\n");
  EXPECT_EQ(encode("control 0.5 -1"),
            "19 0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF F0 00 00 00 00 00 00\n");
  // The document's dialect is the default, as it was.
  EXPECT_EQ(run_hil("encode wr8 --profile document task 1 drive 100").output,
            "03 01 01 04 64 00 00 00\n");
  EXPECT_EQ(run_hil("encode wr8 auth").output, "01 48 49 4C 2D 57 52 38 2D 30 31\n");
}

TEST(HilCli, Wr8ProfileArgumentErrorsNameWhatWasWrong) {
  const auto task = run_hil("encode wr8 --profile svgui-head task 1 forward 100");
  EXPECT_EQ(task.exit_code, 1);
  EXPECT_EQ(task.output,
            "hil encode wr8: profile svgui-head has no form 'task'; its forms are auth, "
            "auth-reply, set, answer, set-request, map, low-freq-data, high-freq-data, control, "
            "packet; profile svgui-2019 has it (see --help)\n");
  const auto control = run_hil("encode wr8 --profile svgui-2019 control 1 2");
  EXPECT_THAT(control.output,
              HasSubstr("profile svgui-2019 has no form 'control'; its forms are auth, "
                        "auth-reply, task, settings, answer, data, packet"));
  const auto set = run_hil("encode wr8 set steering-p=1");
  EXPECT_EQ(set.exit_code, 1);
  EXPECT_THAT(set.output, HasSubstr("unknown form 'set'"));
  EXPECT_THAT(set.output, HasSubstr("profile svgui-head has it: --profile svgui-head"));

  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"svgui-2019 task 1 forward", "task forward takes 1 value(s), got 0"},
           {"svgui-2019 task 1 jump 3",
            "task type 'jump': expected forward, wheels, "
            "turn-signals or 0..255"},
           {"svgui-2019 settings 5 1 2 3", "settings takes COI P I D SERVO_ZERO"},
           {"svgui-2019 answer 7 maybe", "answer code 'maybe': expected error, started, done"},
           {"svgui-2019 data run 5 encoder=1.5", "encoder '1.5' is not a whole number"},
           {"svgui-head answer 7 1", "answer takes CODE (the head programs' ANSWER has no COI)"},
           {"svgui-head set speed=3", "set: 'speed' is none of steering-p, steering-i"},
           {"svgui-head set steering-p=1 steering-p=2", "set: 'steering-p' is given twice"},
           {"svgui-head map 0123 01", "map row 2 has 2 cells, row 1 has 4"},
           {"svgui-head control a 1", "X 'a' is not a number"},
           {"svgui-head low-freq-data busy 5", "state 'busy': expected fault, run, stop, wait"},
           {"svgui-2019 --big-endian auth",
            "--big-endian is an option of profile document, "
            "not of svgui-2019"},
           {"svgui-head map 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 "
            "0123 0123 0123 0123 0123 0123",
            "a packet of 167 bytes; one length byte frames 127"},
       }) {
    const auto r = run_hil("encode wr8 --profile " + args);
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("hil encode wr8: " + says)) << args;
  }
  const auto unknown = run_hil("encode wr8 --profile svgui-2020 auth");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output, HasSubstr("wr8 has no profile 'svgui-2020'; its profiles are "
                                        "document (the default), svgui-2019 and svgui-head"));
  const auto sender = run_hil("decode wr8 --profile svgui-head --sender gui 04 02 01 02 03");
  EXPECT_EQ(sender.exit_code, 1);
  EXPECT_THAT(sender.output, HasSubstr("--sender is an option of profile document"));
}

TEST(HilCli, DecodesSvguiStreamsByTheLengthByte) {
  const auto head = run_hil("decode wr8 --profile svgui-head 04 02 01 02 03 02 05 01");
  EXPECT_EQ(head.exit_code, 0) << head.output;
  EXPECT_EQ(head.output,
            "frame @0  AuthReply device=1 id=2 state=WAIT\n"
            "    raw: 04 02 01 02 03\n"
            "frame @5  Answer code=1\n"
            "    raw: 02 05 01\n");

  // The GUI's login: its bytes in hex, its text masked as everywhere.
  const auto login = run_hil("decode wr8 --profile svgui-2019 0B 01 6B 6F 6E 6E 69 63 68 69 77 61");
  EXPECT_EQ(login.exit_code, 0) << login.output;
  EXPECT_THAT(login.output, HasSubstr("frame @0  Auth text=********** (the GUI's login)\n"));
  EXPECT_EQ(login.output.find("konnichiwa"), std::string::npos) << login.output;

  // Length bytes that cannot be right, a packet its length byte cuts
  // short, and a stream that ends inside a packet: typed errors with their bytes.
  const auto bad = run_hil("decode wr8 --profile svgui-head 9C 00 05 08 03 00 00 00 03 02 01");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_EQ(bad.output,
            "error @0  oversized: length byte 0x9C is negative as a signed char: a packet of 128 "
            "bytes or more cannot be framed  [length]\n"
            "    raw: 9C\n"
            "error @1  bad_format: length byte 0x00 frames no packet  [length]\n"
            "    raw: 00\n"
            "error @2  bad_format: LOW-FREQ-DATA of 5 bytes is cut short at byte 2  "
            "[LOW-FREQ-DATA]\n"
            "    raw: 05 08 03 00 00 00\n"
            "error @8  truncated: the stream ended 2 of 3 packet bytes after its length byte  "
            "[length]\n"
            "    raw: 03 02 01\n");
  // v2019 has no SET-REQUEST: code 6 is its DATA, and one byte is not a DATA.
  const auto request = run_hil("decode wr8 --profile svgui-2019 01 06");
  EXPECT_EQ(request.exit_code, 1);
  EXPECT_THAT(request.output, HasSubstr("bad_format: DATA of 1 bytes is cut short"));
}

TEST(HilCli, DecodesASvguiCaptureFileWithItsProfile) {
  // A vehicle's side of a session of the head programs, as raw bytes on disk.
  const std::string head_data =
      "\x41\x09\x02\x25\x51\x00\x00\x00\x00\x01\x3F\xF8\x00\x00\x00\x00\x00\x00"
      "\x00\x00\x00\x02\xC0\x24\x00\x00\x00\x00\x00\x00\x00\x00\x00\x03\x3F\xD0"
      "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x04\x3F\xE0\x00\x00\x00\x00\x00\x00"
      "\x00\x00\x00\x05\x40\x56\x80\x00\x00\x00\x00\x00"s;
  ASSERT_EQ(head_data.size(), 66U);
  const std::string stream = std::string("\x04\x02\x01\x02\x03", 5) + head_data + head_data;
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-cli-svgui-" + std::to_string(::getpid()) + ".bin");
  {
    std::ofstream out(path, std::ios::binary);
    out << stream;
  }
  const auto r =
      run_hil("decode wr8 --profile svgui-head --no-raw --summary --file " + path.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output,
            "frame @0  AuthReply device=1 id=2 state=WAIT\n"
            "frame @5  HighFreqData t=36000000ms encoder=1.5 steering=-10 x=0.25 y=0.5 angle=90\n"
            "frame @71  HighFreqData t=36000000ms encoder=1.5 steering=-10 x=0.25 y=0.5 angle=90\n"
            "summary: 137 bytes, 3 frame(s), 0 error(s)\n");
  // Read as the document's packets (no length byte), the same bytes are
  // something else entirely.
  const auto document = run_hil("decode wr8 --no-raw --summary --file " + path.string());
  EXPECT_EQ(document.exit_code, 1) << document.output;
  std::filesystem::remove(path);
}

TEST(HilCli, EveryCaptureDecodesWithTheErrorsItWasMadeWith) {
  struct Capture {
    const char* args;
    const char* summary;
  };
  for (const Capture& c : {
           Capture{"arduino --profile readme --file scenarios/captures/arduino-session.txt",
                   "summary: 243 bytes, 15 frame(s), 4 error(s), 1 bad_checksum, 1 bad_format, 1 "
                   "bad_value, 1 garbage"},
           Capture{"wr8 --hex --file scenarios/captures/wr8-vehicle.hex",
                   "summary: 165 bytes, 12 frame(s), 1 error(s), 1 garbage"},
           Capture{"leka --hex --file scenarios/captures/leka-master.hex",
                   "summary: 86 bytes, 6 frame(s), 3 error(s), 1 bad_checksum, 1 bad_value, 1 "
                   "truncated"},
       }) {
    const auto r = run_hil(std::string("decode ") + c.args + " --summary --no-raw");
    EXPECT_THAT(r.output, HasSubstr(c.summary)) << c.args;
  }
}

TEST(HilCli, ProxyRejectsABadEndpointOrFaultFileAndSaysWhere) {
  const auto uri = run_hil("proxy --listen tcp://127.0.0.1:0 --upstream tcp://127.0.0.1");
  EXPECT_EQ(uri.exit_code, 1);
  EXPECT_THAT(uri.output, HasSubstr("expected tcp://HOST:PORT"));

  const auto faults = run_hil(
      "proxy --listen tcp://127.0.0.1:0 --upstream tcp://127.0.0.1:9 --faults "
      "tests/apps/data/bad-faults.yaml");
  EXPECT_EQ(faults.exit_code, 1);
  EXPECT_THAT(faults.output,
              HasSubstr("bad-faults.yaml:4:12: rule 1 (fragment): 'sizes' must be [min, max]"));

  const auto missing = run_hil("proxy --listen tcp://127.0.0.1:0");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("--upstream is required"));
}

TEST(HilCli, WorldCheckReportsEachFileAndTheFirstErrorWithItsPosition) {
  const auto good =
      run_hil("world check scenarios/worlds/warehouse.yaml scenarios/worlds/corridor.yaml");
  EXPECT_EQ(good.exit_code, 0);
  EXPECT_THAT(good.output,
              HasSubstr("warehouse.yaml: ok, 'warehouse', 4.00 x 3.00 m, 2 obstacle(s), "
                        "1 tape(s) 7.71 m long, 2 tag(s): 001 002"));
  EXPECT_THAT(good.output, HasSubstr("corridor.yaml: ok"));

  const auto bad =
      run_hil("world check scenarios/worlds/warehouse.yaml tests/apps/data/bad-world.yaml");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output, HasSubstr("warehouse.yaml: ok"));
  EXPECT_THAT(bad.output, HasSubstr("bad-world.yaml:4:40: obstacles[0].circle.radius_m: expected a "
                                    "positive number of metres, got '-0.2'"));

  const auto missing = run_hil("world check no/such/world.yaml");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("no/such/world.yaml"));
}

TEST(HilCli, WorldRenderDrawsTheBuiltInWarehouseAndWorldFiles) {
  const auto builtin = run_hil("world render");
  EXPECT_EQ(builtin.exit_code, 0);
  EXPECT_THAT(builtin.output, HasSubstr("<svg"));
  EXPECT_THAT(builtin.output, HasSubstr(">001<"));
  EXPECT_THAT(builtin.output, HasSubstr("</svg>"));

  const auto corridor = run_hil("world render scenarios/worlds/corridor.yaml --scale 100");
  EXPECT_EQ(corridor.exit_code, 0);
  EXPECT_THAT(corridor.output, HasSubstr("corridor"));

  const auto bad = run_hil("world render tests/apps/data/bad-world.yaml");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output, HasSubstr("bad-world.yaml:4:40"));
}

TEST(HilCli, WorldDefaultPrintsAWorldFileThatChecksClean) {
  const auto r = run_hil("world default");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("name: warehouse"));
  EXPECT_THAT(r.output, HasSubstr("id: \"002\""));
}

TEST(HilCli, HelpListsEveryProtocol) {
  const auto r = run_hil("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* p : {"logi", "wr8", "arduino", "leka"})
    EXPECT_THAT(r.output, HasSubstr(p));
}

// hil profiles: every car with each profile, its source and how it
// differs; one car alone; an unknown car refused with the list.
TEST(HilCli, ProfilesListsEveryCarsProfilesWithTheirSources) {
  const auto all = run_hil("profiles");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  for (const char* car : {"logi\n", "wr8\n", "arduino\n", "leka\n"})
    EXPECT_THAT(all.output, HasSubstr(car));
  // Long texts are folded at spaces; no line is wider than 100 columns.
  std::size_t widest = 0;
  for (std::size_t at = 0; at < all.output.size();) {
    const std::size_t end = std::min(all.output.find('\n', at), all.output.size());
    widest = std::max(widest, end - at);
    at = end + 1;
  }
  EXPECT_LE(widest, 100U) << all.output;
  // WR8 has the document's dialect and the two versions of the real programs.
  const auto wr8 = run_hil("profiles wr8");
  EXPECT_THAT(wr8.output, HasSubstr("  document (default)\n"));
  EXPECT_THAT(wr8.output,
              HasSubstr("  svgui-2019\n    source: lsd-maddrive/smart_vehicle_gui at 8d80e92"));
  EXPECT_THAT(wr8.output,
              HasSubstr("  svgui-head\n    source: lsd-maddrive/smart_vehicle_gui at 431e8d4"));
  const auto arduino = run_hil("profiles arduino");
  ASSERT_EQ(arduino.exit_code, 0) << arduino.output;
  EXPECT_THAT(arduino.output, HasSubstr("  firmware (default)\n"));
  EXPECT_THAT(arduino.output, HasSubstr("  readme\n"));
  EXPECT_THAT(arduino.output, HasSubstr("andrii-mazurchuk/arduino_robot_steering- at 8dcfab0"));
  EXPECT_EQ(arduino.output.find("leka"), std::string::npos) << arduino.output;
  EXPECT_THAT(arduino.output,
              HasSubstr("    reply latency: 0.000 ms processing, then the line at 9600 baud\n"));
  const auto logi = run_hil("profiles logi");
  EXPECT_THAT(logi.output, HasSubstr("    reply latency: 5.000 ms processing\n"));
  EXPECT_THAT(unfolded(logi.output), HasSubstr("so 5 ms is an estimate"));
  const auto tank = run_hil("profiles tank");
  EXPECT_EQ(tank.exit_code, 2) << tank.output;
  EXPECT_THAT(tank.output,
              HasSubstr("unknown car 'tank'; the cars are logi, wr8, arduino and leka"));
}

// The real client's frames (robot_client.py at 8dcfab0) from hil encode,
// and the real sketch's verdict on the README's frame from hil decode.
TEST(HilCli, ArduinoFirmwareProfileEncodesAndJudgesAsTheRealBoard) {
  const auto ping = run_hil("encode arduino --profile firmware PING");
  EXPECT_EQ(ping.exit_code, 0) << ping.output;
  EXPECT_EQ(ping.output, "^01|PING| *31$\n");
  const auto sonar = run_hil("encode arduino --profile firmware --seq 5 B");
  EXPECT_EQ(sonar.output, "^05|B| *67$\n");
  EXPECT_EQ(run_hil("encode arduino --profile readme PING").output, "^01|PING|*11$\n");

  const auto refused = run_hil("decode arduino --profile firmware '^01|PING|*11$'");
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_THAT(refused.output, HasSubstr("refused ^01|PING|*11$ -> ^01|NACK|BAD_FMT*41$"));
  const auto taken = run_hil("decode arduino --profile firmware '^01|PING| *31$'");
  EXPECT_EQ(taken.exit_code, 0) << taken.output;
  EXPECT_EQ(taken.output, "request Ping seq=01  ^01|PING| *31$\n");
  // The sketch matches commands without regard to case, and reads a number
  // with atol ("abc" is 0): frames it acts on that the typed decoder would
  // not read show as the sketch splits them. A reply read back is typed,
  // with what the board would make of it.
  const auto loose = run_hil("decode arduino '^01|ping| *31$' '^03|V|abc*35$' '^02|ACK|PONG*5D$'");
  EXPECT_EQ(loose.exit_code, 0) << loose.output;
  EXPECT_EQ(
      loose.output,
      "request seq=01 cmd=ping payload=' '  ^01|ping| *31$\n"
      "request seq=03 cmd=V payload='abc'  ^03|V|abc*35$\n"
      "reply (the board answers it NACK BAD_CMD) Ack seq=02 info=\"PONG\"  ^02|ACK|PONG*5D$\n");

  const auto wrong = run_hil("encode arduino --profile sketch PING");
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_THAT(wrong.output, HasSubstr("arduino has no profile 'sketch'; its profiles are firmware "
                                      "(the default) and readme"));
}

// The third-party generator's documented frame (MMyster/Leka-Command-
// Generator) decodes in profile comspecs-v3 and is given back by encode;
// the README profile refuses it and names the one it matches.
TEST(HilCli, LekaComspecsProfileDecodesAndEncodesTheGeneratorsFrame) {
  const auto decoded =
      run_hil("decode leka --profile comspecs-v3 2A 2B 2C 2D 05 16 12 64 96 C8 77");
  EXPECT_EQ(decoded.exit_code, 0) << decoded.output;
  EXPECT_THAT(decoded.output, HasSubstr("led.belt.single led=18 rgb=(100,150,200)"));
  const auto encoded =
      run_hil("encode leka --profile comspecs-v3 led.belt.single 0x12 100 150 200");
  EXPECT_EQ(encoded.exit_code, 0) << encoded.output;
  EXPECT_EQ(encoded.output, "2A 2B 2C 2D 05 16 12 64 96 C8 77\n");
  EXPECT_EQ(run_hil("encode leka led.belt.single 0x12 100 150 200").output,
            "2A 2B 2C 2D 05 15 12 64 96 C8 2F\n");

  const auto readme = run_hil("decode leka 2A 2B 2C 2D 05 16 12 64 96 C8 77");
  EXPECT_EQ(readme.exit_code, 1) << readme.output;
  EXPECT_THAT(readme.output, HasSubstr("does not match 0x2F"));
  EXPECT_THAT(readme.output, HasSubstr("it matches profile comspecs-v3"));

  const auto range = run_hil("encode leka led.ear.range 0 1 255 0 0");
  EXPECT_EQ(range.exit_code, 1) << range.output;
  EXPECT_THAT(range.output, HasSubstr("led.ear.range is not a command of profile readme"));
  EXPECT_EQ(run_hil("encode leka --profile comspecs-v3 led.ear.range 0 1 255 0 0").output,
            "2A 2B 2C 2D 06 12 00 01 FF 00 00 88\n");

  const auto wrong = run_hil("decode leka --profile yaml 2A");
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_THAT(wrong.output, HasSubstr("leka has no profile 'yaml'; its profiles are readme (the "
                                      "default) and comspecs-v3"));
}

}  // namespace
}  // namespace hil::test

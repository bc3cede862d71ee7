// The protocol calculator as QA uses it: examples from the README and the
// protocol documents, and the errors a mistyped command gets.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::test {
namespace {

using ::testing::HasSubstr;
using namespace std::string_literals;

/// A named series of command lines, run in order.
struct CliCase {
  const char* name;
  std::vector<CliRun> runs;
};

class HilCli : public ::testing::TestWithParam<CliCase> {};

TEST_P(HilCli, GivesTheOutputAndExitCodeOfEachRun) {
  for (const CliRun& run : GetParam().runs)
    expect_run(run);
}

std::string case_name(const ::testing::TestParamInfo<CliCase>& info) {
  return info.param.name;
}

std::vector<CliCase> logi_cases() {
  return {
      {"EncodesLogiFromPayload", {prints("encode logi SP:050", 0, "LOGI:SP:050:D7#\n")}},
      {"EncodesLogiStatus",
       {says("encode logi STAT:SP:050,STA:002,RUN:1,MODE:AUTO,MAN:STOP,DIS:123,TRK:0110,"
             "DEV:-3,OBS:0,RPM:1:2:3:4",
             0, {"LOGI:STAT:SP:050,STA:002"})}},
      {"RefusesAnInvalidLogiPayloadAndSaysWhy",
       {says("encode logi SP:101", 1, {"speed percent 000..100", "--raw"})}},
      {"RawFramesAnyLogiPayload", {prints("encode logi --raw SP:5", 0, "LOGI:SP:5:77#\n")}},
      {"DecodesLogiFramesAndReportsErrors",
       {says("decode logi 'LOGI:SP:050:D7#'", 0, {"SetSpeed percent=50"}),
        says("decode logi 'LOGI:SP:050:D8#'", 1,
             {"bad_checksum: checksum D8, computed D7", "raw: LOGI:SP:050:D8#"})}},
      {"LenientLogiDecodeToleratesLowercaseChecksum",
       {says("decode logi 'LOGI:SP:050:d7#'", 1, {"lowercase_checksum"}),
        says("decode logi --lenient 'LOGI:SP:050:d7#'", 0, {"tolerated: lowercase_checksum"})}},
      // The capture holds deliberate errors.
      {"DecodesAStreamFromAFileWithSummary",
       {says("decode logi --no-raw --summary --file scenarios/captures/logi-session.txt", 1,
             {"summary: 739 bytes, 13 frame(s), 4 error(s)"})}},
      {"DecodesHexInput",
       {says("decode logi --hex '4C 4F 47 49 3A 53 50 3A 30 35 30 3A 44 37 23'", 0,
             {"SetSpeed percent=50"})}},
      {"MalformedCommandLinesExitTwoWithAMessage",
       {says("encode logi", 2, {"payload is required"}),
        says("encode nosuchcar X", 2, {"nosuchcar"})}},
      {"UnreadableInputExitsOneWithAMessage",
       {says("decode logi --file /nonexistent/capture", 1, {"cannot open '/nonexistent/capture'"}),
        says("decode logi --hex 'GG'", 1, {"is not hex bytes"}),
        says("decode logi", 1, {"no bytes to decode"})}},
  };
}
INSTANTIATE_TEST_SUITE_P(Logi, HilCli, ::testing::ValuesIn(logi_cases()), case_name);

std::vector<CliCase> arduino_cases() {
  return {
      {"EncodesArduinoWithSequenceNumber",
       {prints("encode arduino --seq 2 V 160", 0, "^02|V|160*63$\n"),
        prints("encode arduino --seq 4 R -90", kAnyExit, "^04|R|-90*72$\n"),
        // The real sketch (the default) wants one space where there is no argument.
        prints("encode arduino --seq 8 STATUS", kAnyExit, "^08|STATUS| *3C$\n"),
        prints("encode arduino --profile readme --seq 8 STATUS", kAnyExit, "^08|STATUS|*1C$\n"),
        prints("encode arduino --seq 2 V:160", kAnyExit, "^02|V|160*63$\n")}},
      {"RefusesArduinoSpeedOutOfRange", {says("encode arduino --seq 2 V 300", 1, {"0..255"})}},
      {"DecodesArduinoRequest",
       {says("decode arduino --profile readme '^02|V|160*63$'", 0, {"SetSpeed seq=02 pwm=160"}),
        // The real sketch's view (the default profile): a request it acts on,
        // typed.
        prints("decode arduino '^02|V|160*63$'", 0,
               "request SetSpeed seq=02 pwm=160  ^02|V|160*63$\n")}},
      // The real client's frames (robot_client.py at 8dcfab0) from hil encode,
      // and the real sketch's verdict on the README's frame from hil decode.
      {"ArduinoFirmwareProfileEncodesAndJudgesAsTheRealBoard",
       {prints("encode arduino --profile firmware PING", 0, "^01|PING| *31$\n"),
        prints("encode arduino --profile firmware --seq 5 B", kAnyExit, "^05|B| *67$\n"),
        prints("encode arduino --profile readme PING", kAnyExit, "^01|PING|*11$\n"),
        says("decode arduino --profile firmware '^01|PING|*11$'", 1,
             {"refused ^01|PING|*11$ -> ^01|NACK|BAD_FMT*41$"}),
        prints("decode arduino --profile firmware '^01|PING| *31$'", 0,
               "request Ping seq=01  ^01|PING| *31$\n"),
        // The sketch matches commands without regard to case, and reads a
        // number with atol ("abc" is 0): frames it acts on that the typed
        // decoder would not read show as the sketch splits them. A reply
        // read back is typed, with what the board would make of it.
        prints("decode arduino '^01|ping| *31$' '^03|V|abc*35$' '^02|ACK|PONG*5D$'", 0,
               "request seq=01 cmd=ping payload=' '  ^01|ping| *31$\n"
               "request seq=03 cmd=V payload='abc'  ^03|V|abc*35$\n"
               "reply (the board answers it NACK BAD_CMD) Ack seq=02 info=\"PONG\"  "
               "^02|ACK|PONG*5D$\n"),
        says("encode arduino --profile sketch PING", kFailure,
             {"arduino has no profile 'sketch'; its profiles are firmware (the default) "
              "and readme"})}},
  };
}
INSTANTIATE_TEST_SUITE_P(Arduino, HilCli, ::testing::ValuesIn(arduino_cases()), case_name);

std::vector<CliCase> leka_cases() {
  return {
      {"EncodesLekaFramesAsSpacedHex",
       {prints("encode leka info", kAnyExit, "2A 2B 2C 2D 01 70 70\n"),
        prints("encode leka led.belt.single 0 255 0 0", kAnyExit,
               "2A 2B 2C 2D 05 15 00 FF 00 00 41\n"),
        says("encode leka led.ear.all 255 0 0 + motor.all 1 200", 0,
             {"2A 2B 2C 2D 07 11 FF 00 00 21 01 C8"})}},
      {"DecodesLekaFrame",
       {says("decode leka 2A 2B 2C 2D 05 15 00 FF 00 00 41", 0, {"led.belt.single"}),
        says("decode leka 2A 2B 2C 2D 05 15 00 FF 00 00 42", 1, {"bad_checksum"})}},
      // The third-party generator's documented frame (MMyster/Leka-Command-
      // Generator) decodes in profile comspecs-v3 and is given back by encode;
      // the README profile refuses it and names the one it matches.
      {"LekaComspecsProfileDecodesAndEncodesTheGeneratorsFrame",
       {says("decode leka --profile comspecs-v3 2A 2B 2C 2D 05 16 12 64 96 C8 77", 0,
             {"led.belt.single led=18 rgb=(100,150,200)"}),
        prints("encode leka --profile comspecs-v3 led.belt.single 0x12 100 150 200", 0,
               "2A 2B 2C 2D 05 16 12 64 96 C8 77\n"),
        prints("encode leka led.belt.single 0x12 100 150 200", kAnyExit,
               "2A 2B 2C 2D 05 15 12 64 96 C8 2F\n"),
        says("decode leka 2A 2B 2C 2D 05 16 12 64 96 C8 77", 1,
             {"does not match 0x2F", "it matches profile comspecs-v3"}),
        says("encode leka led.ear.range 0 1 255 0 0", 1,
             {"led.ear.range is not a command of profile readme"}),
        prints("encode leka --profile comspecs-v3 led.ear.range 0 1 255 0 0", kAnyExit,
               "2A 2B 2C 2D 06 12 00 01 FF 00 00 88\n"),
        says("decode leka --profile yaml 2A", kFailure,
             {"leka has no profile 'yaml'; its profiles are readme (the default) and "
              "comspecs-v3"})}},
  };
}
INSTANTIATE_TEST_SUITE_P(Leka, HilCli, ::testing::ValuesIn(leka_cases()), case_name);

/// `hil encode wr8 --profile <profile_and_form>` succeeds and prints `output`.
CliRun wr8_encodes(const std::string& profile_and_form, const std::string& output) {
  return prints("encode wr8 --profile " + profile_and_form, 0, output);
}

/// The SET packet of the head programs with steering-p 1.5 and
/// forward-int 100, every other of its twelve values 0.
std::string svgui_head_set_packet() {
  const std::string zero = " 00 00 00 00 00 00 00 00";
  std::string set = "61 04 3F F8 00 00 00 00 00 00";  // steering-p 1.5
  for (int i = 1; i < 7; ++i)
    set += zero;
  set += " 40 59 00 00 00 00 00 00";  // forward-int 100
  for (int i = 8; i < 12; ++i)
    set += zero;
  return set + "\n";
}

// The real WR8 programs (smart_vehicle_gui 8d80e92 and 431e8d4) put a
// length byte before every packet: hil encode prints it first, hil decode
// reads by it.
std::vector<CliCase> wr8_encode_cases() {
  return {
      {"EncodesAndDecodesWr8",
       {prints("encode wr8 task 1 drive 100", kAnyExit, "03 01 01 04 64 00 00 00\n"),
        prints("encode wr8 response 1 completed", kAnyExit, "05 01 02\n"),
        says("decode wr8 03 01 01 04 64 00 00 00", 0, {"Task", "100"})}},
      {"EncodesEveryPacketOfSvgui2019WithItsLengthByte",
       {wr8_encodes("svgui-2019 auth", "0B 01 6B 6F 6E 6E 69 63 68 69 77 61\n"),  // konnichiwa
        wr8_encodes("svgui-2019 auth-reply", "04 02 01 02 03\n"),
        wr8_encodes("svgui-2019 auth-reply 1 2 run", "04 02 01 02 01\n"),
        wr8_encodes("svgui-2019 task 7 forward 100", "08 03 07 01 01 64 00 00 00\n"),
        wr8_encodes("svgui-2019 task 1 wheels -15", "08 03 01 02 01 F1 FF FF FF\n"),
        wr8_encodes("svgui-2019 task 3 turn-signals", "04 03 03 03 00\n"),
        wr8_encodes("svgui-2019 task 2 4", "04 03 02 04 00\n"),  // a type the vehicle ignores
        wr8_encodes("svgui-2019 settings 5 3 1 90 100",
                    "12 04 05 03 00 00 00 01 00 00 00 5A 00 00 00 64 00 00 00\n"),
        wr8_encodes("svgui-2019 answer 7 done", "03 05 07 02\n"),
        wr8_encodes("svgui-2019 answer 7 0", "03 05 07 00\n"),
        // 42 bytes after the length byte, big-endian, 4-byte codes before values.
        wr8_encodes("svgui-2019 data run 36000000 encoder=120 steering=1.5 motor-battery=87 "
                    "computer-battery=95",
                    "2A 06 01 02 25 51 00 00 00 00 01 00 00 00 78 00 00 00 02 3F F8 00 00 00 00 "
                    "00 00 00 00 00 03 00 00 00 57 00 00 00 04 00 00 00 5F\n"),
        wr8_encodes("svgui-2019 packet 9 01 02", "03 09 01 02\n")}},
      {"EncodesEveryPacketOfSvguiHeadWithItsLengthByte",
       {wr8_encodes("svgui-head auth", "0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00\n"),  // and NUL
        wr8_encodes("svgui-head auth --text-hex 6B6F", "03 01 6B 6F\n"),
        wr8_encodes("svgui-head auth-reply", "04 02 01 02 03\n"),
        wr8_encodes("svgui-head set steering-p=1.5 forward-int=100", svgui_head_set_packet()),
        wr8_encodes("svgui-head answer applied", "02 05 01\n"),
        wr8_encodes("svgui-head answer 0", "02 05 00\n"),
        wr8_encodes("svgui-head set-request", "01 06\n"),
        wr8_encodes("svgui-head map 01100000 00000000",
                    "1F 07 08 02 00 00 00 02 00 00 00 08 00 01 01 00 00 00 00 00 00 00 00 08 00 "
                    "00 00 00 00 00 00 00\n"),
        wr8_encodes("svgui-head map 1,-1 0,127",
                    "13 07 02 02 00 00 00 02 00 00 00 02 01 FF 00 00 00 02 00 7F\n"),
        wr8_encodes("svgui-head low-freq-data wait 36000000 motor-battery=87 "
                    "computer-battery=95 temperature=41.5",
                    "22 08 03 02 25 51 00 00 00 00 01 00 00 00 57 00 00 00 02 00 00 00 5F 00 00 "
                    "00 03 40 44 C0 00 00 00 00 00\n"),
        wr8_encodes("svgui-head high-freq-data 36000000 encoder=1.5 steering=-10 x=0.25 y=0.5 "
                    "angle=90",
                    "41 09 02 25 51 00 00 00 00 01 3F F8 00 00 00 00 00 00 00 00 00 02 C0 24 00 "
                    "00 00 00 00 00 00 00 00 03 3F D0 00 00 00 00 00 00 00 00 00 04 3F E0 00 00 "
                    "00 00 00 00 00 00 00 05 40 56 80 00 00 00 00 00\n"),
        wr8_encodes("svgui-head control 0.5 -1",
                    "19 0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF F0 00 00 00 00 00 "
                    "00\n"),
        // The document's dialect is the default, as it was.
        prints("encode wr8 --profile document task 1 drive 100", kAnyExit,
               "03 01 01 04 64 00 00 00\n"),
        prints("encode wr8 auth", kAnyExit, "01 48 49 4C 2D 57 52 38 2D 30 31\n")}},
  };
}
INSTANTIATE_TEST_SUITE_P(Wr8Encode, HilCli, ::testing::ValuesIn(wr8_encode_cases()), case_name);

/// The profile forms whose arguments hil encode wr8 refuses, each with
/// what it says.
std::vector<CliRun> wr8_form_errors() {
  std::vector<CliRun> runs;
  for (const auto& [args, error] : std::vector<std::pair<std::string, std::string>>{
           {"svgui-2019 task 1 forward", "task forward takes 1 value(s), got 0"},
           {"svgui-2019 task 1 jump 3",
            "task type 'jump': expected forward, wheels, turn-signals or 0..255"},
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
            "--big-endian is an option of profile document, not of svgui-2019"},
           {"svgui-head map 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 0123 "
            "0123 0123 0123 0123 0123 0123",
            "a packet of 167 bytes; one length byte frames 127"},
       })
    runs.push_back(says("encode wr8 --profile " + args, 1, {"hil encode wr8: " + error}));
  return runs;
}

std::vector<CliCase> wr8_error_cases() {
  std::vector<CliRun> profile_errors = {
      prints("encode wr8 --profile svgui-head task 1 forward 100", 1,
             "hil encode wr8: profile svgui-head has no form 'task'; its forms are auth, "
             "auth-reply, set, answer, set-request, map, low-freq-data, high-freq-data, "
             "control, packet; profile svgui-2019 has it (see --help)\n"),
      says("encode wr8 --profile svgui-2019 control 1 2", kAnyExit,
           {"profile svgui-2019 has no form 'control'; its forms are auth, auth-reply, "
            "task, settings, answer, data, packet"}),
      says("encode wr8 set steering-p=1", 1,
           {"unknown form 'set'", "profile svgui-head has it: --profile svgui-head"})};
  for (CliRun& run : wr8_form_errors())
    profile_errors.push_back(std::move(run));
  profile_errors.push_back(
      says("encode wr8 --profile svgui-2020 auth", 2,
           {"wr8 has no profile 'svgui-2020'; its profiles are document (the default), "
            "svgui-2019 and svgui-head"}));
  profile_errors.push_back(says("decode wr8 --profile svgui-head --sender gui 04 02 01 02 03", 1,
                                {"--sender is an option of profile document"}));
  return {
      {"Wr8ProfileArgumentErrorsNameWhatWasWrong", profile_errors},
      {"DecodesSvguiStreamsByTheLengthByte",
       {prints("decode wr8 --profile svgui-head 04 02 01 02 03 02 05 01", 0,
               "frame @0  AuthReply device=1 id=2 state=WAIT\n"
               "    raw: 04 02 01 02 03\n"
               "frame @5  Answer code=1\n"
               "    raw: 02 05 01\n"),
        // The GUI's login: its bytes in hex, its text masked as everywhere.
        {.args = "decode wr8 --profile svgui-2019 0B 01 6B 6F 6E 6E 69 63 68 69 77 61",
         .exit_code = 0,
         .contains = {"frame @0  Auth text=********** (the GUI's login)\n"},
         .lacks = {"konnichiwa"}},
        // Length bytes that cannot be right, a packet its length byte cuts
        // short, and a stream that ends inside a packet: typed errors with
        // their bytes.
        prints("decode wr8 --profile svgui-head 9C 00 05 08 03 00 00 00 03 02 01", 1,
               "error @0  oversized: length byte 0x9C is negative as a signed char: a packet "
               "of 128 bytes or more cannot be framed  [length]\n"
               "    raw: 9C\n"
               "error @1  bad_format: length byte 0x00 frames no packet  [length]\n"
               "    raw: 00\n"
               "error @2  bad_format: LOW-FREQ-DATA of 5 bytes is cut short at byte 2  "
               "[LOW-FREQ-DATA]\n"
               "    raw: 05 08 03 00 00 00\n"
               "error @8  truncated: the stream ended 2 of 3 packet bytes after its length "
               "byte  [length]\n"
               "    raw: 03 02 01\n"),
        // v2019 has no SET-REQUEST: code 6 is its DATA, and one byte is not a DATA.
        says("decode wr8 --profile svgui-2019 01 06", 1,
             {"bad_format: DATA of 1 bytes is cut short"})}},
  };
}
INSTANTIATE_TEST_SUITE_P(Wr8Errors, HilCli, ::testing::ValuesIn(wr8_error_cases()), case_name);

std::vector<CliCase> tool_cases() {
  return {
      {"EveryCaptureDecodesWithTheErrorsItWasMadeWith",
       {says("decode arduino --profile readme --file scenarios/captures/arduino-session.txt "
             "--summary --no-raw",
             kAnyExit,
             {"summary: 243 bytes, 15 frame(s), 4 error(s), 1 bad_checksum, 1 "
              "bad_format, 1 bad_value, 1 garbage"}),
        says("decode wr8 --hex --file scenarios/captures/wr8-vehicle.hex --summary --no-raw",
             kAnyExit, {"summary: 165 bytes, 12 frame(s), 1 error(s), 1 garbage"}),
        says("decode leka --hex --file scenarios/captures/leka-master.hex --summary --no-raw",
             kAnyExit,
             {"summary: 86 bytes, 6 frame(s), 3 error(s), 1 bad_checksum, 1 bad_value, "
              "1 truncated"})}},
      {"ProxyRejectsABadEndpointOrFaultFileAndSaysWhere",
       {says("proxy --listen tcp://127.0.0.1:0 --upstream tcp://127.0.0.1", 1,
             {"expected tcp://HOST:PORT"}),
        says("proxy --listen tcp://127.0.0.1:0 --upstream tcp://127.0.0.1:9 --faults "
             "tests/apps/data/bad-faults.yaml",
             1, {"bad-faults.yaml:4:12: rule 1 (fragment): 'sizes' must be [min, max]"}),
        says("proxy --listen tcp://127.0.0.1:0", 2, {"--upstream is required"})}},
      {"WorldCheckReportsEachFileAndTheFirstErrorWithItsPosition",
       {says("world check scenarios/worlds/warehouse.yaml scenarios/worlds/corridor.yaml", 0,
             {"warehouse.yaml: ok, 'warehouse', 4.00 x 3.00 m, 2 obstacle(s), 1 tape(s) "
              "7.71 m long, 2 tag(s): 001 002",
              "corridor.yaml: ok"}),
        says("world check scenarios/worlds/warehouse.yaml tests/apps/data/bad-world.yaml", 1,
             {"warehouse.yaml: ok",
              "bad-world.yaml:4:40: obstacles[0].circle.radius_m: expected a positive "
              "number of metres, got '-0.2'"}),
        says("world check no/such/world.yaml", 1, {"no/such/world.yaml"})}},
      {"WorldRenderDrawsTheBuiltInWarehouseAndWorldFiles",
       {says("world render", 0, {"<svg", ">001<", "</svg>"}),
        says("world render scenarios/worlds/corridor.yaml --scale 100", 0, {"corridor"}),
        says("world render tests/apps/data/bad-world.yaml", 1, {"bad-world.yaml:4:40"})}},
      {"WorldDefaultPrintsAWorldFileThatChecksClean",
       {says("world default", 0, {"name: warehouse", "id: \"002\""})}},
      {"HelpListsEveryProtocol", {says("--help", 0, {"logi", "wr8", "arduino", "leka"})}},
  };
}
INSTANTIATE_TEST_SUITE_P(Tools, HilCli, ::testing::ValuesIn(tool_cases()), case_name);

TEST(HilCliFiles, DecodesASvguiCaptureFileWithItsProfile) {
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

// hil profiles: every car with each profile, its source and how it
// differs; one car alone; an unknown car refused with the list.
TEST(HilCliProfiles, ProfilesListsEveryCarsProfilesWithTheirSources) {
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

}  // namespace
}  // namespace hil::test

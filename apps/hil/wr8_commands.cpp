// hil encode wr8 / hil decode wr8.

#include <array>
#include <charconv>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include "apps/common/program.hpp"
#include "apps/hil/cli_common.hpp"
#include "apps/hil/wr8_cli.hpp"
#include "link/capture/wire_log.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::apps {
namespace wr8_cli {

namespace wr8 = protocol::wr8;

std::uint32_t parse_unsigned(std::string_view text, std::uint32_t max, std::string_view what) {
  std::uint32_t value = 0;
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    text.remove_prefix(2);
    base = 16;
  }
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || value > max) {
    throw UsageError(std::string(what) + " '" + std::string(text) + "' is not a number 0.." +
                     std::to_string(max));
  }
  return value;
}

std::uint8_t parse_byte(std::string_view text, std::string_view what) {
  return static_cast<std::uint8_t>(parse_unsigned(text, 255, what));
}

wr8::State parse_state_arg(std::string_view text) {
  const auto s = wr8::parse_state(text);
  if (!s)
    throw UsageError("state '" + std::string(text) + "': expected fault, run, stop, wait or 0..3");
  return *s;
}

std::pair<std::string_view, std::string_view> split_assignment(std::string_view arg) {
  const auto eq = arg.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    throw UsageError("'" + std::string(arg) + "' is not NAME=VALUE");
  }
  return {arg.substr(0, eq), arg.substr(eq + 1)};
}

std::string normalised(std::string_view name) {
  std::string out(name);
  for (char& c : out) {
    if (c == '-') c = '_';
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

protocol::Bytes parse_hex_arg(std::string_view text, std::string_view what) {
  const auto bytes = protocol::parse_hex(text);
  if (!bytes) throw UsageError(std::string(what) + " '" + std::string(text) + "' is not hex bytes");
  return *bytes;
}

void expect_count(const std::vector<std::string>& w, std::size_t min, std::size_t max,
                  std::string_view usage) {
  if (w.size() - 1 < min || w.size() - 1 > max) {
    throw UsageError(w[0] + " takes " + std::string(usage));
  }
}

}  // namespace wr8_cli

namespace {

using namespace wr8_cli;

namespace wr8 = protocol::wr8;
namespace svgui = protocol::wr8::svgui;

const char* const kWr8EncodeFooter =
    R"(Forms of --profile document, the default (the WR8 document's packets, no length byte;
prints the packet as spaced hex):
  hil encode wr8 empty
  hil encode wr8 auth [TEXT]               TEXT: exactly 10 characters (default: the
                                           profile string HIL-WR8-01)
  hil encode wr8 auth --text-hex HEX       any 10 bytes as hex
  hil encode wr8 auth-reply DEVICE_CODE DEVICE_ID STATE
  hil encode wr8 task COI TASK [VALUE...]  TASK: check | drive DISTANCE_CM | turn ANGLE_DEG
                                           | blink | get-settings   (or 0..4)
  hil encode wr8 settings COI NAME=VALUE...  NAME: p | i | d | servo-zero (or 0..3)
  hil encode wr8 response COI CODE         CODE: error | started | completed (or 0..2)
  hil encode wr8 data STATE TIMESTAMP_MS [NAME=VALUE...] [--unparsed HEX]
                                           NAME: odometry (cm, int) | speed (m/s, float)
                                           | wheel-angle or angle (deg, float)
                                           | battery (percent, 0..255)   (or the code 0..3)
  hil encode wr8 packet CODE [HEX...]      CODE then the bytes as given, no checks

  STATE: fault | run | stop | wait (or 0..3). COI, DEVICE_CODE, DEVICE_ID, CODE: 0..255.
  A VALUE is read as the profile types it (P, I, D floats; distance, angle, servo
  zero integers); 0x followed by hex digits gives the exact bits instead.
  Put '--' before the form when a value is negative and looks like an option.)";

const char* const kWr8EncodeExamples = R"(
Examples:
  hil encode wr8 auth                         01 48 49 4C 2D 57 52 38 2D 30 31
  hil encode wr8 task 1 drive 100             03 01 01 04 64 00 00 00
  hil encode wr8 task 2 turn -15              03 02 02 04 F1 FF FF FF
  hil encode wr8 settings 5 p=1.5 servo-zero=90
  hil encode wr8 response 1 completed         05 01 02
  hil encode wr8 data run 1500 odometry=120 speed=0.5 angle=-10 battery=87
  hil encode wr8 --big-endian task 1 drive 100
  hil encode wr8 --unchecked task 1 drive     (a drive task with no distance)
  hil encode wr8 packet 3 01 01 06 00 00 00 00 00 00   (a size byte not a multiple of 4)
  hil encode wr8 --profile svgui-2019 auth              0B 01 6B 6F 6E 6E 69 63 68 69 77 61
  hil encode wr8 --profile svgui-2019 task 7 forward 100
                                                        08 03 07 01 01 64 00 00 00
  hil encode wr8 --profile svgui-2019 answer 7 done     03 05 07 02
  hil encode wr8 --profile svgui-head auth              0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00
  hil encode wr8 --profile svgui-head auth-reply        04 02 01 02 03
  hil encode wr8 --profile svgui-head control 0.5 -1    19 0A 00 00 00 01 3F E0 00 00 00 00
                                                        00 00 00 00 00 02 BF F0 00 00 00 00
                                                        00 00
  hil encode wr8 --profile svgui-head answer applied    02 05 01
  hil encode wr8 --profile svgui-head set steering-p=1.5
                                                        61 04 3F F8 00 00 ... (98 bytes: 0x61 = 97
                                                        after the length byte)
)";

const char* const kWr8DecodeFooter = R"(Prints one line per packet or error, with the stream offset.
Examples:
  hil decode wr8 03 01 01 04 64 00 00 00
  hil decode wr8 --sender vehicle 06 01 DC 05 00 00 07 00 78 00 00 00 03 57
  hil decode wr8 --block-unit entries 03 01 01 01 64 00 00 00
  hil decode wr8 --file capture.bin
  hil decode wr8 --profile svgui-head 04 02 01 02 03 02 05 01
      frame @0  AuthReply device=1 id=2 state=WAIT
          raw: 04 02 01 02 03
      frame @5  Answer code=1
          raw: 02 05 01
  hil decode wr8 --profile svgui-2019 --file capture.bin   (a length byte before every packet)
In profiles svgui-2019 and svgui-head every packet is read after its length byte; a length
byte of 00, or of 80 and above (128 bytes or more), is an error of that one byte.
Exit status: 0 all packets decoded; 1 an error was reported, nothing to decode, or input
that cannot be read; 2 a malformed command line.
)";

struct DocumentArgs {
  bool big_endian = false;
  std::string block_unit = "bytes";
};

// The document dialect's own choices (protocol/wr8/profile.hpp); the
// options return so that the real programs' profiles can refuse them.
std::vector<CLI::Option*> add_document_options(CLI::App& cmd, DocumentArgs& args) {
  return {cmd.add_flag("--big-endian", args.big_endian,
                       "Profile document: multi-byte values most significant byte first "
                       "(default: little-endian)"),
          cmd.add_option("--block-unit", args.block_unit,
                         "Profile document: what TASK/SETTINGS/DATA size bytes count: bytes "
                         "(default) or entries")
              ->check(CLI::IsMember({"bytes", "entries"}))};
}

wr8::Profile profile_of(const DocumentArgs& args) {
  wr8::Profile p;
  p.byte_order = args.big_endian ? wr8::ByteOrder::big : wr8::ByteOrder::little;
  p.block_unit =
      args.block_unit == "entries" ? wr8::BlockSizeUnit::entries : wr8::BlockSizeUnit::bytes;
  return p;
}

wr8::Word parse_word(std::string_view text, wr8::ValueType type, std::size_t size,
                     std::string_view what) {
  const auto w = wr8::parse_value(text, type, size);
  if (!w) {
    const char* expected = type == wr8::ValueType::float32      ? "a number"
                           : type == wr8::ValueType::signed_int ? "a whole number"
                                                                : "a whole number >= 0";
    throw UsageError(std::string(what) + " value '" + std::string(text) + "': expected " +
                     expected + " that fits " + std::to_string(size) +
                     " byte(s), or 0x and hex digits");
  }
  return *w;
}

struct Wr8EncodeArgs {
  std::vector<std::string> words;
  std::string profile;  ///< --profile: document (empty), svgui-2019 or svgui-head
  DocumentArgs document;
  bool unchecked = false;
  std::string text_hex;
  std::string unparsed;
};

// A code by its name, or with --unchecked any byte; else a UsageError
// naming `what` and the `expected` names ("task 'UP': expected check, ...").
template <class Code>
Code named_code(std::string_view word, std::optional<Code> named, bool unchecked,
                std::string_view byte_what, std::string_view what, std::string_view expected) {
  if (named) return *named;
  if (unchecked) return static_cast<Code>(parse_byte(word, byte_what));
  throw UsageError(std::string(what) + " '" + std::string(word) + "': expected " +
                   std::string(expected));
}

// The type of the values the profile gives code `index`; signed for a
// code it does not know (sent with --unchecked).
template <std::size_t N>
wr8::ValueType value_type(const std::array<wr8::ValueType, N>& types, std::size_t index) {
  return index < N ? types[index] : wr8::ValueType::signed_int;
}

// A message whose first word is its COI, once the words are counted.
template <class Message>
Message coi_message(const std::vector<std::string>& w, std::size_t min, std::size_t max,
                    std::string_view usage) {
  expect_count(w, min, max, usage);
  Message m;
  m.coi = parse_byte(w[1], "COI");
  return m;
}

wr8::Auth auth_message(const Wr8EncodeArgs& a, const wr8::Profile& profile) {
  const auto& w = a.words;
  expect_count(w, 0, 1, "[TEXT] (10 characters) or --text-hex HEX");
  wr8::Auth m{profile.auth_text};
  if (!a.text_hex.empty() && w.size() > 1)
    throw UsageError("auth takes TEXT or --text-hex, not both");
  protocol::Bytes text;
  if (!a.text_hex.empty()) text = parse_hex_arg(a.text_hex, "--text-hex");
  if (w.size() > 1) text = protocol::to_bytes(w[1]);
  if (!a.text_hex.empty() || w.size() > 1) {
    if (text.size() != wr8::kAuthTextBytes) {
      throw UsageError("the authentication string must be exactly 10 bytes, got " +
                       std::to_string(text.size()));
    }
    std::copy(text.begin(), text.end(), m.text.begin());
  }
  return m;
}

wr8::Task task_message(const Wr8EncodeArgs& a, const wr8::Profile& profile) {
  const auto& w = a.words;
  auto m = coi_message<wr8::Task>(w, 2, 255, "COI TASK [VALUE...]");
  m.task = named_code(w[2], wr8::parse_task(w[2]), a.unchecked, "task code", "task",
                      "check, drive, turn, blink, get-settings or 0..4");
  const auto index = static_cast<std::size_t>(m.task);
  const auto type = value_type(profile.task_value_type, index);
  for (std::size_t i = 3; i < w.size(); ++i)
    m.params.push_back(parse_word(w[i], type, 4, "task"));
  if (!a.unchecked && index < wr8::kTaskCount &&
      m.params.size() != profile.task_parameter_count[index]) {
    throw UsageError("task " + std::string(wr8::to_string(m.task)) + " takes " +
                     std::to_string(profile.task_parameter_count[index]) + " value(s), got " +
                     std::to_string(m.params.size()) + " (--unchecked sends it anyway)");
  }
  return m;
}

wr8::Settings settings_message(const Wr8EncodeArgs& a, const wr8::Profile& profile) {
  const auto& w = a.words;
  auto m = coi_message<wr8::Settings>(w, 1, 255, "COI NAME=VALUE...");
  for (std::size_t i = 2; i < w.size(); ++i) {
    const auto [name, value] = split_assignment(w[i]);
    const auto code = named_code(name, wr8::parse_setting(name), a.unchecked, "setting type",
                                 "setting", "p, i, d, servo-zero or 0..3");
    const auto type = value_type(profile.setting_value_type, static_cast<std::size_t>(code));
    m.params.push_back(wr8::Setting{code, parse_word(value, type, 4, name)});
  }
  return m;
}

wr8::Response response_message(const Wr8EncodeArgs& a) {
  const auto& w = a.words;
  auto m = coi_message<wr8::Response>(w, 2, 2, "COI CODE");
  m.code = named_code(w[2], wr8::parse_response(w[2]), a.unchecked, "response code",
                      "response code", "error, started, completed or 0..2");
  return m;
}

wr8::Data data_message(const Wr8EncodeArgs& a, const wr8::Profile& profile) {
  const auto& w = a.words;
  expect_count(w, 2, 257, "STATE TIMESTAMP_MS [NAME=VALUE...]");
  wr8::Data m;
  m.state = parse_state_arg(w[1]);
  m.timestamp_ms = parse_unsigned(w[2], 0xFFFFFFFFu, "timestamp");
  for (std::size_t i = 3; i < w.size(); ++i) {
    const auto [name, value] = split_assignment(w[i]);
    std::string key = normalised(name);
    if (key == "angle") key = "wheel_angle";
    const wr8::DataParameter* p = profile.data_parameter(key);
    if (p == nullptr && !key.empty() && key[0] >= '0' && key[0] <= '9') {
      p = profile.data_parameter(parse_byte(key, "DATA code"));
    }
    if (p == nullptr) {
      throw UsageError(
          "DATA parameter '" + std::string(name) +
          "': expected odometry, speed, wheel-angle, battery or a code the profile sizes");
    }
    m.values.push_back(wr8::DataValue{p->code, parse_word(value, p->type, p->size_bytes, p->name)});
  }
  if (!a.unparsed.empty()) m.unparsed = parse_hex_arg(a.unparsed, "--unparsed");
  return m;
}

// `packet CODE [HEX...]`: any code and body, framed as they are.
protocol::Bytes any_packet(const std::vector<std::string>& w) {
  expect_count(w, 1, 100000, "CODE [HEX...]");
  protocol::Bytes body;
  for (std::size_t i = 2; i < w.size(); ++i) {
    const auto b = parse_hex_arg(w[i], "packet byte(s)");
    body.insert(body.end(), b.begin(), b.end());
  }
  return wr8::raw_packet(parse_byte(w[1], "packet code"), body);
}

// Builds the packet the words describe; throws UsageError for bad words.
protocol::Bytes build_packet(const Wr8EncodeArgs& a, const wr8::Profile& profile) {
  const auto& w = a.words;
  const std::string form = normalised(w[0]);
  const auto encode = [&](const wr8::Message& m) {
    return a.unchecked ? wr8::encode_unchecked(m, profile) : wr8::encode(m, profile);
  };
  if (form == "empty") {
    expect_count(w, 0, 0, "no arguments");
    return encode(wr8::Empty{});
  }
  if (form == "auth") return encode(auth_message(a, profile));
  if (form == "auth_reply") {
    expect_count(w, 3, 3, "DEVICE_CODE DEVICE_ID STATE");
    return encode(wr8::AuthReply{parse_byte(w[1], "device code"), parse_byte(w[2], "device id"),
                                 parse_state_arg(w[3])});
  }
  if (form == "task") return encode(task_message(a, profile));
  if (form == "settings") return encode(settings_message(a, profile));
  if (form == "response") return encode(response_message(a));
  if (form == "data") return encode(data_message(a, profile));
  if (form == "packet") return any_packet(w);
  std::string message = "unknown form '" + w[0] +
                        "': expected empty, auth, auth-reply, task, settings, response, data or "
                        "packet (see --help)";
  const std::string_view other = svgui_profile_with_form(w[0]);
  if (!other.empty()) {
    message += "; profile " + std::string(other) + " has it: --profile " + std::string(other);
  }
  throw UsageError(message);
}

constexpr std::string_view kWr8ProfileHelp =
    "document (the default): the WR8 document's packets, no length byte; svgui-2019 or "
    "svgui-head: the real smart_vehicle_gui programs, a length byte before every packet";

// The first document-only option given with a profile of the real
// programs, as an error to print; empty when there is none.
std::string document_only_given(const std::vector<CLI::Option*>& options,
                                std::string_view profile) {
  for (const CLI::Option* o : options) {
    if (o->count() > 0) {
      return o->get_name() + " is an option of profile document, not of " + std::string(profile);
    }
  }
  return {};
}

// The codec's words without its own "WR8 ... encode: " prefix, which ours repeats.
std::string_view codec_words(std::string_view what) {
  for (const std::string_view prefix :
       {"WR8 encode: ", "WR8 (smart_vehicle_gui) encode: ", "WR8 length prefix: "}) {
    if (what.starts_with(prefix)) return what.substr(prefix.size());
  }
  return what;
}

}  // namespace

void register_wr8(CommandSet& commands) {
  auto enc_args = std::make_shared<Wr8EncodeArgs>();
  auto* enc = commands.encode.add_subcommand(
      "wr8", "WR8 packet from a form and its fields, e.g. task 1 drive 100");
  enc->add_option("form", enc_args->words, "FORM [ARGS...]: see the forms below")->required();
  add_profile_option(*enc, enc_args->profile, "wr8", std::string(kWr8ProfileHelp));
  auto document_only = add_document_options(*enc, enc_args->document);
  document_only.push_back(enc->add_flag(
      "--unchecked", enc_args->unchecked,
      "Profile document: skip the profile's checks (parameter counts, codes outside the "
      "tables): fault injection"));
  enc->add_option("--text-hex", enc_args->text_hex,
                  "auth: the string as hex (10 bytes in profile document, the exact bytes "
                  "after the code in the others)");
  document_only.push_back(enc->add_option(
      "--unparsed", enc_args->unparsed,
      "Profile document, data: bytes appended to the block after the values (start with an "
      "unknown code)"));
  enc->footer(std::string(kWr8EncodeFooter) + kSvguiEncodeForms + kWr8EncodeExamples);
  enc->callback([&run = commands.run, enc_args, document_only] {
    run = [enc_args, document_only]() -> int {
      try {
        const auto version = svgui::version_of_profile(enc_args->profile);
        protocol::Bytes packet;
        if (version) {
          const std::string refused = document_only_given(document_only, enc_args->profile);
          if (!refused.empty()) throw UsageError(refused);
          packet = build_svgui_packet(enc_args->words, enc_args->text_hex, *version);
        } else {
          packet = build_packet(*enc_args, profile_of(enc_args->document));
        }
        std::cout << protocol::to_hex(packet) << '\n';
        return 0;
      } catch (const UsageError& e) {
        std::cerr << "hil encode wr8: " << e.what() << '\n';
      } catch (const std::invalid_argument& e) {
        std::cerr << "hil encode wr8: " << codec_words(e.what()) << '\n';
      }
      return 1;
    };
  });

  struct DecodeArgs {
    DecodeInput input;
    std::string profile;
    DocumentArgs document;
    std::string sender = "any";
    std::size_t max_packet = 0;
  };
  auto dec_args = std::make_shared<DecodeArgs>();
  auto* dec = commands.decode.add_subcommand("wr8", "Decode WR8 packets or a WR8 byte stream");
  add_decode_input(*dec, dec_args->input, true);
  add_profile_option(*dec, dec_args->profile, "wr8", std::string(kWr8ProfileHelp));
  auto dec_document_only = add_document_options(*dec, dec_args->document);
  dec_document_only.push_back(
      dec->add_option("--sender", dec_args->sender,
                      "Profile document: whose packets to expect: any (default), gui or "
                      "vehicle; the other side's codes are reported as unknown_code")
          ->check(CLI::IsMember({"any", "gui", "vehicle"})));
  dec_document_only.push_back(dec->add_option(
      "--max-packet", dec_args->max_packet,
      "Profile document: longest packet in bytes (at least 16); longer ones are reported as "
      "oversized. Default: the longest the profile can declare"));
  dec->footer(kWr8DecodeFooter);
  dec->callback([&run = commands.run, dec_args, dec_document_only] {
    run = [dec_args, dec_document_only]() -> int {
      const auto bytes = read_decode_input(dec_args->input, true);
      if (const auto version = svgui::version_of_profile(dec_args->profile)) {
        const std::string refused = document_only_given(dec_document_only, dec_args->profile);
        if (!refused.empty()) {
          std::cerr << "hil decode wr8: " << refused << '\n';
          return 1;
        }
        return decode_svgui(bytes, dec_args->input, *version);
      }
      wr8::DecoderOptions options;
      options.profile = profile_of(dec_args->document);
      options.sender = dec_args->sender == "gui"       ? wr8::Sender::gui
                       : dec_args->sender == "vehicle" ? wr8::Sender::vehicle
                                                       : wr8::Sender::any;
      options.max_packet_bytes = dec_args->max_packet;
      if (options.max_packet_bytes != 0 && options.max_packet_bytes < wr8::kMinPacketLimit) {
        std::cerr << "hil decode wr8: --max-packet " << options.max_packet_bytes << " is below "
                  << wr8::kMinPacketLimit << " (an AUTH packet alone is 11 bytes)\n";
        return 1;
      }
      const wr8::Profile profile = options.profile;
      return print_items<wr8::Message>(wr8::Decoder(std::move(options)), bytes, true,
                                       dec_args->input, [profile](const wr8::Message& m) {
                                         // A capture may hold the real login: the hex above shows
                                         // the bytes, the decoded line only whether they match the
                                         // profile.
                                         const std::string text = wr8::describe(m, profile);
                                         return std::holds_alternative<wr8::Auth>(m)
                                                    ? link::masked_frame_text("AUTH", text)
                                                    : text;
                                       });
    };
  });
}

}  // namespace hil::apps

// hil encode leka / hil decode leka.

#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "apps/common/program.hpp"
#include "apps/hil/cli_common.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/leka/codec.hpp"

namespace hil::apps {
namespace {

namespace leka = protocol::leka;

const char* const kLekaEncodeForms = R"(Forms:
  hil encode leka COMMAND [VALUE...] [+ COMMAND [VALUE...]]...
      One frame whose command group holds the commands in order ('+' between
      commands). VALUEs are bytes 0..255, decimal or 0x hex.
  hil encode leka --group HEX
      Frames any group bytes as given (start sequence, length, group, checksum),
      unchecked: for odd or broken frames (unknown ids, cut-short commands, an
      empty or oversized group).
)";

const char* const kLekaEncodeExamples = R"(
Examples:
  hil encode leka info                          -> 2A 2B 2C 2D 01 70 70
  hil encode leka led.belt.single 0 255 0 0     -> 2A 2B 2C 2D 05 15 00 FF 00 00 41
  hil encode leka --profile comspecs-v3 led.belt.single 0x12 100 150 200
                                                -> 2A 2B 2C 2D 05 16 12 64 96 C8 77
  hil encode leka led.ear.all 255 0 0 + motor.all 1 200
  hil encode leka motivator 0x52
  hil encode leka --unchecked led.ear.single 2 0 0 255
  hil encode leka --group "99 01 02"
)";

// The command table of the help text, from kCommandSpecs: the id in each
// profile, then the values.
std::string encode_footer() {
  std::string text = kLekaEncodeForms;
  text += "\nCommands (id in profile readme / comspecs-v3, values):\n";
  for (const leka::CommandSpec& s : leka::kCommandSpecs) {
    const auto id = [](std::uint8_t v) {
      return v == 0 ? std::string("  -  ") : protocol::hex_literal(v);
    };
    std::string line = "  " + std::string(s.name);
    line.resize(19, ' ');
    line += id(s.readme_id) + " / " + id(s.comspecs_id) + "  " +
            (s.data_bytes == 0 ? std::string("-") : std::string(s.data_help));
    text += line + "\n";
  }
  text += "  (belt LED ids 0..19, see --max-belt-id; FIRST <= LAST in ranges)\n";
  return text + kLekaEncodeExamples;
}

const char* const kLekaDecodeFooter = R"(Examples:
  hil decode leka 2A 2B 2C 2D 01 70 70
  hil decode leka --profile comspecs-v3 2A 2B 2C 2D 05 16 12 64 96 C8 77
  hil decode leka "2A2B2C2D0515 00FF000041"
  hil decode leka --file capture.bin --no-raw
  hil decode leka --lenient 2A 2B 2C 2D 05 12 02 00 00 FF 00

Exit status: 0 every item is a frame, 1 some error was found, 2 nothing to decode.
Errors: garbage, bad_checksum, bad_format (length 0, command cut short),
bad_value (id or spin out of range), oversized (length over the frame bound),
unknown_code (unknown command id), truncated (stream ended inside a frame).
)";

// The words of the command line as a command group; throws
// std::invalid_argument with a message for the user.
leka::CommandGroup parse_words(const std::vector<std::string>& words, leka::Dialect dialect) {
  leka::CommandGroup group;
  std::size_t i = 0;
  while (i <= words.size()) {
    const std::size_t number = group.commands.size() + 1;
    if (i == words.size() || words[i] == "+") {
      throw std::invalid_argument("command " + std::to_string(number) +
                                  " is missing (nothing before or after a '+')");
    }
    const leka::CommandSpec* spec = leka::find_spec(words[i]);
    if (spec == nullptr) {
      std::string known;
      for (const auto& s : leka::kCommandSpecs)
        known += (known.empty() ? "" : ", ") + std::string(s.name);
      throw std::invalid_argument("unknown command '" + words[i] + "'; known commands: " + known);
    }
    if (!spec->in(dialect)) {
      throw std::invalid_argument(std::string(spec->name) + " is not a command of profile " +
                                  std::string(leka::to_string(dialect)) +
                                  " (--profile comspecs-v3 has it)");
    }
    std::size_t end = i + 1;
    while (end < words.size() && words[end] != "+")
      ++end;
    const std::size_t given = end - i - 1;
    if (given != spec->data_bytes) {
      throw std::invalid_argument(
          std::string(spec->name) + " takes " + std::to_string(spec->data_bytes) + " value(s)" +
          (spec->data_bytes == 0 ? std::string() : " (" + std::string(spec->data_help) + ")") +
          ", got " + std::to_string(given));
    }
    protocol::Bytes data;
    for (std::size_t k = i + 1; k < end; ++k) {
      const auto b = parse_byte_text(words[k], 5);  // "00255", "0x0FF" at the longest
      if (!b) {
        throw std::invalid_argument(std::string(spec->name) + " value " + std::to_string(k - i) +
                                    " '" + words[k] + "' is not a byte 0..255 (decimal or 0x hex)");
      }
      data.push_back(*b);
    }
    group.commands.push_back(*leka::make_command(*spec, data));
    if (end == words.size()) break;
    i = end + 1;
  }
  return group;
}

constexpr const char* kProfileHelp =
    "readme (the default: the README's ids and checksum) or comspecs-v3 (the spec's YAML ids "
    "and the 8-bit checksum over length and group)";

}  // namespace

void register_leka(CommandSet& commands) {
  struct Args {
    std::string profile;
    std::vector<std::string> words;
    std::string group_hex;
    bool unchecked = false;
    int max_belt_id = 0x13;
    bool lenient = false;
    std::size_t max_frame_bytes = leka::kMaxFrameBytes;
    DecodeInput input;
  };
  auto args = std::make_shared<Args>();

  auto* enc = commands.encode.add_subcommand(
      "leka",
      "Leka Alpha frame from commands, e.g. 'led.belt.single 0 255 0 0' or 'info + stop.motor'");
  add_profile_option(*enc, args->profile, "leka", kProfileHelp);
  enc->add_option("command", args->words, "COMMAND [VALUE...], several joined by '+' (see below)");
  enc->add_option("--group", args->group_hex,
                  "Frame these command-group bytes (hex) unchecked instead of commands");
  enc->add_flag("--unchecked", args->unchecked,
                "Do not check ids, spins and the 122-byte group bound (for odd frames)");
  enc->add_option("--max-belt-id", args->max_belt_id,
                  "Highest belt LED id accepted (default 19 = 0x13; the seed table says 0x19)")
      ->check(CLI::Range(0, 255));
  enc->footer(encode_footer());
  enc->callback([&run = commands.run, args] {
    run = [args]() -> int {
      try {
        const leka::Dialect dialect = leka::dialect_named(args->profile);
        if (!args->group_hex.empty() && !args->words.empty()) {
          throw std::invalid_argument("give either commands or --group, not both");
        }
        if (!args->group_hex.empty()) {
          const auto group = protocol::parse_hex(args->group_hex);
          if (!group)
            throw std::invalid_argument("--group '" + args->group_hex + "' is not hex bytes");
          std::cout << protocol::to_hex(leka::frame_group(*group, dialect)) << '\n';
          return 0;
        }
        if (args->words.empty()) {
          throw std::invalid_argument("no command given (try 'hil encode leka --help')");
        }
        const auto group = parse_words(args->words, dialect);
        if (args->unchecked) {
          std::cout << protocol::to_hex(
                           leka::frame_group(leka::group_bytes(group, dialect), dialect))
                    << '\n';
          return 0;
        }
        const leka::ValueLimits limits{static_cast<std::uint8_t>(args->max_belt_id)};
        std::cout << protocol::to_hex(leka::encode(group, limits, dialect)) << '\n';
        return 0;
      } catch (const std::invalid_argument& e) {
        std::string what = e.what();
        if (what.rfind("Leka encode: ", 0) == 0) {
          what = what.substr(13) + "\n(use --unchecked or --group to send it anyway)";
        }
        std::cerr << "hil encode leka: " << what << '\n';
        return 1;
      }
    };
  });

  auto* dec = commands.decode.add_subcommand("leka", "Decode Leka Alpha frames or a byte stream");
  add_decode_input(*dec, args->input, true);
  add_profile_option(*dec, args->profile, "leka", kProfileHelp);
  dec->add_flag("--lenient", args->lenient,
                "Accept ids and spins out of range (frame reported as tolerated bad_value)");
  dec->add_option("--max-belt-id", args->max_belt_id,
                  "Highest belt LED id accepted (default 19 = 0x13)")
      ->check(CLI::Range(0, 255));
  dec->add_option("--max-frame-bytes", args->max_frame_bytes,
                  "Frame bound in bytes (default 128, the robot's serial buffer)")
      ->check(CLI::Range(7, 261));
  dec->footer(kLekaDecodeFooter);
  dec->callback([&run = commands.run, args] {
    run = [args]() -> int {
      protocol::Bytes bytes;
      try {
        bytes = read_decode_input(args->input, true);
      } catch (const CLI::ValidationError& e) {
        std::cerr << "hil decode leka: " << e.what() << '\n';
        return 1;
      }
      leka::DecoderOptions options;
      options.max_frame_bytes = args->max_frame_bytes;
      options.limits.max_belt_led_id = static_cast<std::uint8_t>(args->max_belt_id);
      options.accept_out_of_range = args->lenient;
      options.dialect = leka::dialect_named(args->profile);
      return print_items<leka::Message>(leka::Decoder(options), bytes, true, args->input,
                                        [](const leka::Message& m) { return leka::describe(m); });
    };
  });
}

}  // namespace hil::apps

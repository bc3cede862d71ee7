// hil encode arduino / hil decode arduino.

#include <cctype>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "apps/common/program.hpp"
#include "apps/hil/cli_common.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/sketch.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::apps {
namespace {

namespace ard = protocol::arduino;

constexpr const char* kArduinoEncodeFooter = R"(Forms (SEQ is --seq, default 1):
  hil encode arduino [--seq N] CMD [PAYLOAD...]     typed, checked: V 0..255, M/R -32768..32767
  hil encode arduino [--seq N] CMD:PAYLOAD          the same as one token, like the robot CLI (V:160)
  hil encode arduino [--seq N] --raw CMD [PAYLOAD]  any CMD/PAYLOAD text, unchecked (fault injection)
  hil encode arduino --body 'TEXT'                  frame TEXT as the whole part between ^ and *
  add --checksum XX to any form to write XX instead of the computed checksum
Commands: PING STATUS V <pwm> M <cm> R <deg> S B I HELP (lowercase accepted),
  responses ACK [info text] and NACK <BAD_CS|BAD_FMT|BAD_SEQ|BAD_CMD|BAD_V|other text>.
  Several PAYLOAD words are joined with single spaces (ACK moved 25 cm).
--seq takes decimal 0..255 or hex with a 0x prefix (0x00..0xFF): --seq 31 and --seq 0x1F agree.
Examples:
  hil encode arduino --seq 2 V 160            ^02|V|160*63$
  hil encode arduino --seq 4 R -90            ^04|R|-90*72$
  hil encode arduino --seq 8 STATUS           ^08|STATUS| *3C$  (the real sketch wants one space)
  hil encode arduino --seq 1 ACK OK           ^01|ACK|OK*4C$
  hil encode arduino --seq 4 NACK BAD_CS      ^04|NACK|BAD_CS*0B$
  hil encode arduino --seq 9 --raw JUMP HIGH  ^09|JUMP|HIGH*05$
  hil encode arduino --body 'G1|PING|'        ^G1|PING|*66$
  hil encode arduino --seq 2 V 160 --checksum 00   ^02|V|160*00$
  hil encode arduino --profile readme PING    ^01|PING|*11$  (the README's empty payload))";

constexpr const char* kArduinoDecodeFooter =
    R"(Frames on the command line are joined in order and decoded as one stream;
quote them, the shell treats ^ $ | * specially. Exit status: 0 all frames, 1 any error, 2 no bytes.
Examples:
  hil decode arduino '^02|V|160*63$'                what the real sketch takes from it
  hil decode arduino '^01|PING|*11$'                the README's PING: the sketch answers BAD_FMT
  hil decode arduino --profile readme '^01|PING|*11$^01|ACK|OK*4C$'
  hil decode arduino --profile readme --nack '^2A|S|*00$'   also print the NACK it answers
  hil decode arduino --profile readme --firmware -f capture.bin  the 96-byte frame bound
  hil decode arduino --hex '5E 30 37 7C 53 7C 20 2A 37 34 24')";

std::string upper(std::string text) {
  for (char& c : text)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

struct ArduinoEncodeArgs {
  std::string profile;
  std::string seq = "1";
  std::vector<std::string> words;
  bool raw = false;
  std::string body;
  std::string checksum;
};

int fail(const std::string& what) {
  std::cerr << "hil encode arduino: " << what << '\n';
  return 1;
}

// CMD and PAYLOAD from the words: "V 160", "V:160", "ACK moved 25 cm".
std::pair<std::string, std::string> split_words(const std::vector<std::string>& words) {
  std::string cmd = words.front();
  std::string payload;
  if (words.size() == 1) {
    const auto colon = cmd.find(':');
    if (colon != std::string::npos) {
      payload = cmd.substr(colon + 1);
      cmd.resize(colon);
    }
  }
  for (std::size_t i = 1; i < words.size(); ++i) {
    if (i > 1) payload.push_back(' ');
    payload += words[i];
  }
  return {cmd, payload};
}

int run_encode(const ArduinoEncodeArgs& args, bool body_given, bool seq_given) {
  if (!args.checksum.empty() && args.checksum.size() != 2) {
    return fail("--checksum '" + args.checksum + "' is not exactly two characters");
  }
  std::string frame;
  if (body_given) {
    if (!args.words.empty() || seq_given || args.raw) {
      return fail("--body frames its text alone; drop the CMD/PAYLOAD words, --seq and --raw");
    }
    frame = ard::frame_body(args.body);
  } else {
    if (args.words.empty()) {
      return fail("give a command, e.g. 'V 160', 'V:160', 'ACK OK' (see --help)");
    }
    const auto seq = parse_byte_text(args.seq, 4);  // up to 0xFF
    if (!seq) {
      return fail("--seq '" + args.seq + "' is not 0..255 in decimal or 0x00..0xFF in hex");
    }
    auto [cmd, payload] = split_words(args.words);
    if (args.raw) {
      frame = ard::frame_text(ard::Envelope{*seq, cmd, payload});
    } else {
      const ard::Envelope envelope{*seq, upper(cmd), payload};
      auto typed = ard::to_message(envelope);
      if (const auto* e = std::get_if<ard::PayloadError>(&typed)) {
        return fail(std::string(protocol::to_string(e->kind)) + ": " + e->detail +
                    "\n(use --raw to frame it anyway)");
      }
      try {
        frame = ard::encode_text(std::get<ard::Message>(typed), ard::dialect_named(args.profile));
      } catch (const std::invalid_argument& e) {
        return fail(std::string(e.what()) + "\n(use --raw to frame it anyway)");
      }
    }
  }
  if (!args.checksum.empty()) {
    // Replace the two digits between the last '*' and the '$'.
    frame.replace(frame.size() - 3, 2, args.checksum);
  }
  std::cout << frame << '\n';
  return 0;
}

struct DecodeArgs {
  std::string profile;
  DecodeInput input;
  bool firmware = false;
  bool strict_checksum = false;
  std::string max_frame_bytes;
  bool nack = false;
};

// What a frame the sketch stores means: the typed request (or, for a
// board's reply read back, the typed answer) when the firmware profile's
// decoder reads it, else the sketch's own split of it.
std::string sketch_request_text(const ard::SketchFrame& frame, const ard::SketchRequest& r) {
  const auto item = ard::decode_frame(frame.raw, ard::Dialect::firmware);
  if (const auto* f = std::get_if<protocol::Frame<ard::Message>>(&item)) {
    const bool request = ard::is_request(f->message.body);
    return std::string(request ? "request " : "reply (the board answers it NACK BAD_CMD) ") +
           ard::describe(f->message);
  }
  return "request seq=" + r.seq + " cmd=" + r.cmd + " payload='" + r.payload + "'";
}

// The real sketch's verdict on each frame it would store: acted on,
// refused with a NACK (the reply printed), or dropped without a word.
int run_sketch_decode(const protocol::Bytes& bytes) {
  ard::SketchReceiver receiver;
  std::vector<ard::SketchFrame> frames;
  receiver.feed(bytes, frames);
  int status = 0;
  for (const auto& frame : frames) {
    const std::string raw(frame.raw.begin(), frame.raw.end());
    std::visit(protocol::Overloaded{
                   [&](const ard::SketchRequest& r) {
                     std::cout << sketch_request_text(frame, r) << "  " << raw << '\n';
                   },
                   [&](const ard::SketchRefusal& r) {
                     status = 1;
                     std::cout << "refused " << raw << " -> "
                               << ard::sketch_frame(r.seq, "NACK", ard::to_string(r.code)) << '\n';
                   },
                   [&](const ard::SketchDrop& d) {
                     status = 1;
                     std::cout << "dropped without an answer " << raw << ": " << d.reason << '\n';
                   },
               },
               frame.verdict);
  }
  if (receiver.buffered() > 0) {
    status = 1;
    std::cout << "incomplete: " << receiver.buffered() << " byte(s) wait for '$'\n";
  }
  if (frames.empty() && receiver.buffered() == 0) {
    if (bytes.empty()) return 2;
    std::cout << "ignored: " << bytes.size()
              << " byte(s) and no '^' the sketch would start a frame at\n";
    return 1;
  }
  return status;
}

int run_decode(const DecodeArgs& args) {
  protocol::Bytes bytes;
  try {
    bytes = read_decode_input(args.input, false);
  } catch (const CLI::Error& e) {
    std::cerr << "hil decode arduino: " << e.what() << '\n';
    return 1;
  }
  try {
    if (ard::dialect_named(args.profile) == ard::Dialect::firmware) return run_sketch_decode(bytes);
  } catch (const protocol::ProfileError& e) {
    std::cerr << "hil decode arduino: --profile: " << e.what() << '\n';
    return 1;
  }
  ard::DecoderOptions options =
      args.firmware ? ard::DecoderOptions::firmware() : ard::DecoderOptions{};
  if (!args.max_frame_bytes.empty()) {
    const auto bound = protocol::parse_decimal(args.max_frame_bytes, false, false, 7);
    if (!bound || *bound < static_cast<long long>(ard::kMinFrameBytes)) {
      std::cerr << "hil decode arduino: --max-frame-bytes '" << args.max_frame_bytes
                << "' is not a whole number of at least " << ard::kMinFrameBytes
                << " (the shortest frame, ^00|S|*00$)\n";
      return 1;
    }
    options.max_frame_bytes = static_cast<std::size_t>(*bound);
  }
  options.accept_lowercase_checksum = !args.strict_checksum;
  const int status =
      print_items<ard::Message>(ard::Decoder(options), bytes, false, args.input,
                                [](const ard::Message& m) { return ard::describe(m); });
  if (args.nack) {
    // The answers the mock firmware gives: one NACK per complete frame that
    // failed to decode, in stream order.
    ard::Decoder decoder(options);
    std::vector<ard::Item> items;
    decoder.feed(bytes, items);
    decoder.finish(items);
    std::size_t offset = 0;
    for (const auto& item : items) {
      if (const auto* e = std::get_if<protocol::DecodeError>(&item)) {
        if (const auto answer = ard::nack_response(*e)) {
          std::cout << "nack for error @" << offset << ": " << ard::encode_text(*answer) << '\n';
        }
        offset += e->raw.size();
      } else {
        offset += std::get<protocol::Frame<ard::Message>>(item).raw.size();
      }
    }
  }
  return status;
}

}  // namespace

void register_arduino(CommandSet& commands) {
  auto encode_args = std::make_shared<ArduinoEncodeArgs>();
  auto decode_args = std::make_shared<DecodeArgs>();

  auto* enc = commands.encode.add_subcommand(
      "arduino", "Arduino robot frame ^SEQ|CMD|PAYLOAD*CS$, e.g. --seq 2 V 160 or ACK OK");
  add_profile_option(*enc, encode_args->profile, "arduino",
                     "firmware (the default): argument-less requests with the one-space payload "
                     "the real sketch needs; or readme, the README's empty payload");
  enc->add_option("words", encode_args->words,
                  "CMD then PAYLOAD words (V 160), or one CMD:PAYLOAD token (V:160)");
  auto* seq = enc->add_option("--seq", encode_args->seq,
                              "Sequence number: decimal 0..255 or hex 0x00..0xFF (default 1)");
  enc->add_flag("--raw", encode_args->raw,
                "Frame CMD and PAYLOAD as given, without checking them (for odd frames)");
  auto* body = enc->add_option("--body", encode_args->body,
                               "Frame this text as everything between ^ and * (e.g. 'G1|PING|')");
  enc->add_option("--checksum", encode_args->checksum,
                  "Write these two characters instead of the computed checksum (fault injection)");
  enc->footer(kArduinoEncodeFooter);
  enc->callback([&run = commands.run, encode_args, body, seq] {
    run = [encode_args, body = body->count() > 0, seq = seq->count() > 0]() {
      return run_encode(*encode_args, body, seq);
    };
  });

  auto* dec =
      commands.decode.add_subcommand("arduino", "Decode Arduino robot frames or a byte stream");
  add_decode_input(*dec, decode_args->input, false);
  add_profile_option(*dec, decode_args->profile, "arduino",
                     "firmware (the default): what the real sketch does with each frame (acted "
                     "on, refused with a NACK, or dropped); or readme, the README's rules");
  dec->add_flag("--firmware", decode_args->firmware,
                "Use the firmware's 96-byte frame bound instead of the PC's 256-byte guard");
  dec->add_option("--max-frame-bytes", decode_args->max_frame_bytes,
                  "Frame bound in bytes, markers included (default 256, 96 with --firmware)");
  dec->add_flag("--strict-checksum", decode_args->strict_checksum,
                "Lowercase checksum hex is an error (default: accepted, shown as tolerated)");
  dec->add_flag("--nack", decode_args->nack,
                "Also print the NACK frame the firmware answers each bad frame with");
  dec->footer(kArduinoDecodeFooter);
  dec->callback([&run = commands.run, decode_args] {
    run = [decode_args]() { return run_decode(*decode_args); };
  });
}

}  // namespace hil::apps

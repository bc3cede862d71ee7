#include "apps/hil/cli_common.hpp"

#include <fstream>
#include <iterator>

namespace hil::apps {

void add_decode_input(CLI::App& cmd, DecodeInput& input, bool binary) {
  cmd.add_option("frames", input.frames,
                 binary ? "Frame bytes as hex, e.g. 2A 2B 2C 2D 01 70 70 (spaces optional)"
                        : "Frames as text (use --hex to give them as hex)");
  cmd.add_option("-f,--file", input.file,
                 "Decode a raw byte stream read from a file ('-' for stdin)");
  cmd.add_flag("--hex", input.hex,
               binary ? "The --file holds hex text (e.g. a pasted capture), not raw bytes"
                      : "The frames (and --file) are hex text, not raw bytes");
  cmd.add_flag("!--no-raw", input.show_raw, "Do not print the raw bytes of decoded frames");
  cmd.add_flag("--summary", input.summary, "End with the number of frames and of errors by kind");
  cmd.footer(
      "Prints one line per frame or error with its byte offset; errors show the raw bytes.\n"
      "Exit status: 0 every frame valid; 1 an error found, or input that cannot be read;\n"
      "2 a malformed command line.");
}

protocol::Bytes read_decode_input(const DecodeInput& input, bool binary) {
  protocol::Bytes bytes;
  if (!input.file.empty()) {
    if (input.file == "-") {
      bytes.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
      std::ifstream in(input.file, std::ios::binary);
      if (!in) throw CLI::ValidationError("--file", "cannot open '" + input.file + "'");
      bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    if (input.hex) {
      const auto parsed = protocol::parse_hex(protocol::to_string(bytes));
      if (!parsed)
        throw CLI::ValidationError("--file",
                                   "'" + input.file + "' is not hex text (pairs of 0-9 A-F)");
      bytes = *parsed;
    }
  }
  for (std::size_t i = 0; i < input.frames.size(); ++i) {
    const std::string& arg = input.frames[i];
    if (binary || input.hex) {
      const auto parsed = protocol::parse_hex(arg);
      if (!parsed) {
        throw CLI::ValidationError("frames", "argument " + std::to_string(i + 1) + " '" + arg +
                                                 "' is not hex bytes (pairs of 0-9 A-F)");
      }
      bytes.insert(bytes.end(), parsed->begin(), parsed->end());
    } else {
      bytes.insert(bytes.end(), arg.begin(), arg.end());
    }
  }
  return bytes;
}

std::optional<std::uint8_t> parse_byte_text(std::string_view text, std::size_t max_chars) {
  if (text.empty() || text.size() > max_chars) return std::nullopt;
  unsigned base = 10;
  std::string_view digits = text;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    base = 16;
    digits.remove_prefix(2);
  }
  unsigned value = 0;
  for (const char c : digits) {
    unsigned d = 0;
    if (c >= '0' && c <= '9') {
      d = static_cast<unsigned>(c - '0');
    } else if (base == 16 && c >= 'a' && c <= 'f') {
      d = static_cast<unsigned>(c - 'a' + 10);
    } else if (base == 16 && c >= 'A' && c <= 'F') {
      d = static_cast<unsigned>(c - 'A' + 10);
    } else {
      return std::nullopt;
    }
    value = value * base + d;
  }
  if (value > 255) return std::nullopt;
  return static_cast<std::uint8_t>(value);
}

std::string render_bytes(protocol::ByteView bytes, bool binary) {
  return binary ? protocol::to_hex(bytes) : protocol::escape(bytes);
}

}  // namespace hil::apps

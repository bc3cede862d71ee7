#pragma once
// Pieces every `hil encode` / `hil decode` protocol command shares.

#include <CLI/CLI.hpp>

#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::apps {

/// Where `hil decode <protocol>` takes its bytes from.
struct DecodeInput {
  std::vector<std::string> frames;  ///< frames on the command line (joined, in order)
  std::string file;                 ///< a raw byte stream from a file, "-" for stdin
  bool hex = false;                 ///< the file / command-line frames are hex text, not raw bytes
  bool show_raw = true;             ///< print each frame's raw bytes too
  bool summary = false;             ///< end with a count of frames and errors by kind
};

/// Adds the positional frames and --file/--hex/--no-raw options.
void add_decode_input(CLI::App& cmd, DecodeInput& input, bool binary);

/// The bytes to decode. Throws CLI::ValidationError with a precise message
/// when the input is unreadable or bad hex.
protocol::Bytes read_decode_input(const DecodeInput& input, bool binary);

/// A byte written in decimal (0..255) or as 0x and hex digits ("0x2A");
/// nullopt for anything else, or for text of more than `max_chars`
/// characters (leading zeros count).
std::optional<std::uint8_t> parse_byte_text(std::string_view text, std::size_t max_chars);

/// How a protocol renders bytes for a person: text protocols as escaped
/// text, binary ones as spaced uppercase hex.
std::string render_bytes(protocol::ByteView bytes, bool binary);

/// Prints one line per decoded item; returns the exit status: 0 when every
/// item is a frame, 1 when any error was found or there was nothing to decode.
template <class Message, class Decoder>
int print_items(Decoder decoder, protocol::ByteView bytes, bool binary, const DecodeInput& input,
                const std::function<std::string(const Message&)>& describe,
                std::ostream& out = std::cout) {
  std::vector<protocol::DecodeItem<Message>> items;
  decoder.feed(bytes, items);
  decoder.finish(items);
  int status = items.empty() ? 1 : 0;
  std::size_t offset = 0;
  for (const auto& item : items) {
    if (const auto* f = std::get_if<protocol::Frame<Message>>(&item)) {
      out << "frame @" << offset << "  " << describe(f->message);
      if (f->tolerated) out << "  (tolerated: " << protocol::to_string(*f->tolerated) << ')';
      if (input.show_raw) out << "\n    raw: " << render_bytes(f->raw, binary);
      out << '\n';
      offset += f->raw.size();
    } else {
      const auto& e = std::get<protocol::DecodeError>(item);
      out << "error @" << offset << "  " << protocol::to_string(e.kind) << ": " << e.detail;
      if (!e.context.empty()) out << "  [" << e.context << ']';
      out << "\n    raw: " << render_bytes(e.raw, binary) << '\n';
      offset += e.raw.size();
      status = 1;
    }
  }
  if (items.empty()) out << "no bytes to decode\n";
  if (input.summary) {
    std::map<std::string_view, std::size_t> errors;
    std::size_t frames = 0;
    for (const auto& item : items) {
      if (const auto* e = std::get_if<protocol::DecodeError>(&item)) {
        ++errors[protocol::to_string(e->kind)];
      } else {
        ++frames;
      }
    }
    out << "summary: " << offset << " bytes, " << frames << " frame(s), " << (items.size() - frames)
        << " error(s)";
    for (const auto& [kind, n] : errors)
      out << ", " << n << ' ' << kind;
    out << '\n';
  }
  return status;
}

/// Registers `hil encode <name>` and `hil decode <name>` for one protocol.
/// `run` is set to the action the parsed command line selects; it returns the
/// exit status.
struct CommandSet {
  CLI::App& encode;
  CLI::App& decode;
  std::function<int()>& run;
};

void register_logi(CommandSet& commands);
void register_wr8(CommandSet& commands);
void register_arduino(CommandSet& commands);
void register_leka(CommandSet& commands);

/// Registers `hil proxy`.
void register_proxy(CLI::App& app, std::function<int()>& run);

/// Registers `hil world` (check, render, default).
void register_world(CLI::App& app, std::function<int()>& run);
/// `hil mock`: standalone mock cars in real time (apps/hil/mock_command.cpp).
void register_mock(CLI::App& app, std::function<int()>& run);
/// `hil run`: scenario files, the table, JUnit and the report folder (apps/hil/run_command.cpp).
void register_run(CLI::App& app, std::function<int()>& run);
/// `hil conform probe` and `hil conform check` (conform_command.cpp).
void register_conform(CLI::App& app, std::function<int()>& run);
/// hil profiles [CAR]: the registry of car profiles (protocol/common/car_profile.hpp).
void register_profiles(CLI::App& app, std::function<int()>& run);
/// `hil firmware build`: an Arduino sketch into the emulated Uno's ELF (firmware_command.cpp).
void register_firmware(CLI::App& app, std::function<int()>& run);
/// `hil report merge`: the results of CI shards joined into one (report_command.cpp).
void register_report(CLI::App& app, std::function<int()>& run);

}  // namespace hil::apps

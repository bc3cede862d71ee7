#pragma once
// What `hil encode wr8` and `hil decode wr8` share between the document's
// dialect (wr8_commands.cpp) and the real programs' profiles svgui-2019 and
// svgui-head (wr8_svgui_commands.cpp).

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "apps/hil/cli_common.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/wr8/message.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::apps::wr8_cli {

/// What was wrong with the command line, for stderr.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Decimal, or 0x and hex digits; at most `max`. `what` names the argument
/// in the error.
std::uint32_t parse_unsigned(std::string_view text, std::uint32_t max, std::string_view what);
std::uint8_t parse_byte(std::string_view text, std::string_view what);
/// fault, run, stop, wait (any case) or 0..3.
protocol::wr8::State parse_state_arg(std::string_view text);
/// NAME=VALUE split at the first '='.
std::pair<std::string_view, std::string_view> split_assignment(std::string_view arg);
/// Lower case with '-' written '_': how form and field names are compared.
std::string normalised(std::string_view name);
protocol::Bytes parse_hex_arg(std::string_view text, std::string_view what);
/// `w[0]` is the form; it takes between `min` and `max` words after it.
void expect_count(const std::vector<std::string>& w, std::size_t min, std::size_t max,
                  std::string_view usage);

// ---- the real programs' profiles ----

/// The forms of `hil encode wr8 --profile P` for svgui-2019 and svgui-head,
/// for the help footer.
extern const char* const kSvguiEncodeForms;

/// The forms one version has, comma-separated: "auth, auth-reply, task, ...".
std::string svgui_forms(protocol::wr8::svgui::Version version);

/// The profile (svgui-2019 or svgui-head) that has form `form` (a form name
/// as typed), preferring head; empty when neither has it.
std::string_view svgui_profile_with_form(std::string_view form);

/// The packet `words` describe (a form and its arguments), with its length
/// byte in front, as the real programs of `version` send it. `text_hex`
/// (--text-hex) gives an AUTH's bytes exactly. Throws UsageError for words
/// that describe no packet, std::invalid_argument (the codec's) for one that
/// cannot be framed.
protocol::Bytes build_svgui_packet(const std::vector<std::string>& words,
                                   const std::string& text_hex,
                                   protocol::wr8::svgui::Version version);

/// `hil decode wr8 --profile svgui-2019|svgui-head`: one line per length-
/// prefixed packet or error; the exit status.
int decode_svgui(protocol::ByteView bytes, const DecodeInput& input,
                 protocol::wr8::svgui::Version version);

}  // namespace hil::apps::wr8_cli

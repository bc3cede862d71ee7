// hil encode logi / hil decode logi.

#include <memory>
#include <variant>

#include "apps/hil/cli_common.hpp"
#include "protocol/logi/codec.hpp"

namespace hil::apps {

void register_logi(CommandSet& commands) {
  namespace logi = protocol::logi;
  struct Args {
    std::string payload;
    bool raw = false;
    bool lenient = false;
    DecodeInput input;
  };
  auto args = std::make_shared<Args>();

  auto* enc =
      commands.encode.add_subcommand("logi", "LOGI frame from its payload, e.g. SP:050 or MV:FWD");
  enc->add_option("payload", args->payload,
                  "Payload: SP:xxx ST:RUN ST:STOP GS:xxx MD:MAN MD:AUTO MV:<dir> FB:<CMD>:<0|1> "
                  "STAT:SP:..,STA:..,RUN:..,MODE:..,MAN:..,DIS:..,TRK:..,DEV:..,OBS:..,RPM:a:b:c:d")
      ->required();
  enc->add_flag("--raw", args->raw,
                "Frame the payload as given, without checking it (for odd frames)");
  enc->callback([&run = commands.run, args] {
    run = [args]() -> int {
      if (args->raw) {
        std::cout << logi::frame_text(args->payload) << '\n';
        return 0;
      }
      auto parsed = logi::parse_payload(args->payload);
      if (const auto* e = std::get_if<logi::PayloadError>(&parsed)) {
        std::cerr << "hil encode logi: " << protocol::to_string(e->kind) << ": " << e->detail
                  << "\n(use --raw to frame it anyway)\n";
        return 1;
      }
      std::cout << logi::encode_text(std::get<logi::Message>(parsed)) << '\n';
      return 0;
    };
  });

  auto* dec = commands.decode.add_subcommand("logi", "Decode LOGI frames or a LOGI byte stream");
  add_decode_input(*dec, args->input, false);
  dec->add_flag("--lenient", args->lenient,
                "Accept lowercase checksum hex (reported as tolerated)");
  dec->callback([&run = commands.run, args] {
    run = [args]() -> int {
      const auto bytes = read_decode_input(args->input, false);
      logi::DecoderOptions options;
      options.accept_lowercase_checksum = args->lenient;
      return print_items<logi::Message>(logi::Decoder(options), bytes, false, args->input,
                                        [](const logi::Message& m) { return logi::describe(m); });
    };
  });
}

}  // namespace hil::apps

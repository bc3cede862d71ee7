// hil: hardware-in-the-loop harness and mock cars for robot-car clients.
// This file only wires the subcommands together.

#include <CLI/CLI.hpp>

#include <csignal>
#include <functional>
#include <iostream>
#include <string_view>

#include "apps/common/program.hpp"
#include "apps/common/version.hpp"
#include "apps/hil/cli_common.hpp"

int main(int argc, char** argv) {
  // Before any thread starts: `hil mock`, `hil proxy` and `hil conform
  // probe` stop on these even when started with them blocked.
  hil::apps::unblock_signals({SIGINT, SIGTERM});
  CLI::App app{"hil: test harness and mock cars for robot-car client software"};
  app.require_subcommand(1);
  app.set_version_flag("--version", hil::apps::version_line("hil"));
  app.footer(
      "Protocols: logi (TCP, ASCII), wr8 (TCP, binary), arduino (serial, ASCII), leka (serial, "
      "binary).\n"
      "Examples:\n"
      "  hil encode logi SP:050                      LOGI:SP:050:D7#\n"
      "  hil encode wr8 task 1 drive 100             03 01 01 04 64 00 00 00\n"
      "  hil encode arduino --seq 2 V 160            ^02|V|160*63$\n"
      "  hil encode leka led.belt.single 0 255 0 0   2A 2B 2C 2D 05 15 00 FF 00 00 41\n"
      "  hil decode logi 'LOGI:SP:050:D7#'\n"
      "  hil decode leka --hex --file capture.hex --summary\n"
      "  hil world check scenarios/worlds/*.yaml\n"
      "  hil world render scenarios/worlds/corridor.yaml -o corridor.svg\n"
      "  hil run scenarios/ --junit hil.xml --report-dir hil-report\n"
      "  hil report merge --junit hil.xml shard-1.xml shard-2.xml  join CI shards' results\n"
      "  hil profiles                                each car's dialects and their sources\n"
      "  hil conform probe arduino --target pty:///dev/ttyUSB0 -o car.ndjson\n"
      "  hil conform check car.ndjson --all-profiles  which profile the car plays\n"
      "  hil firmware build robot/robot.ino -o robot.elf  an Arduino sketch for the emulated Uno\n"
      "Run 'hil encode <protocol> --help' or 'hil decode <protocol> --help' for every form.\n");

  auto* encode =
      app.add_subcommand("encode", "Print the frame for a message (binary frames as hex)");
  encode->require_subcommand(1);
  auto* decode = app.add_subcommand(
      "decode", "Decode frames or a byte stream and print every frame and error");
  decode->require_subcommand(1);

  std::function<int()> run;
  hil::apps::CommandSet commands{*encode, *decode, run};
  hil::apps::register_logi(commands);
  hil::apps::register_wr8(commands);
  hil::apps::register_arduino(commands);
  hil::apps::register_leka(commands);
  hil::apps::register_proxy(app, run);
  hil::apps::register_world(app, run);
  hil::apps::register_mock(app, run);
  hil::apps::register_run(app, run);
  hil::apps::register_profiles(app, run);
  hil::apps::register_conform(app, run);
  hil::apps::register_firmware(app, run);
  hil::apps::register_report(app, run);

  // CLI11 would only say "A subcommand is required"; name the protocols instead.
  if (argc >= 3 &&
      (std::string_view(argv[1]) == "encode" || std::string_view(argv[1]) == "decode") &&
      argv[2][0] != '-') {
    const std::string_view protocol = argv[2];
    if (protocol != "logi" && protocol != "wr8" && protocol != "arduino" && protocol != "leka") {
      std::cerr << "hil " << argv[1] << ": unknown protocol '" << protocol
                << "' (expected logi, wr8, arduino or leka)\n";
      return 2;
    }
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a malformed command line exits 2.
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return run ? run() : 0;
  } catch (const CLI::Error& e) {
    // Well-formed command, unusable input (unreadable file, bad hex, ...).
    std::cerr << "hil: " << e.what() << '\n';
    return 1;
  }
}

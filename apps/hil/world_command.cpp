// hil world: check, draw and print arena (world) files for the simulation.

#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "apps/hil/cli_common.hpp"
#include "sim/arena_yaml.hpp"
#include "sim/svg.hpp"

namespace hil::apps {

namespace {

std::string describe(const sim::Arena& arena) {
  double tape_m = 0;
  for (const auto& tape : arena.tapes)
    tape_m += tape.length_m();
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << "'" << arena.name << "', " << arena.width_m << " x "
      << arena.height_m << " m, " << arena.obstacles.size() << " obstacle(s), "
      << arena.tapes.size() << " tape(s) " << tape_m << " m long, " << arena.tags.size()
      << " tag(s)";
  if (!arena.tags.empty()) {
    out << ":";
    for (const auto& tag : arena.tags)
      out << ' ' << tag.id;
  }
  return out.str();
}

/// The arena in `path`, or the built-in warehouse for an empty path.
sim::Arena arena_from(const std::string& path) {
  return path.empty() ? sim::default_warehouse_arena() : sim::load_arena(path);
}

}  // namespace

void register_world(CLI::App& app, std::function<int()>& run) {
  auto* world = app.add_subcommand("world", "Check, draw or print arena files (scenarios/worlds/)");
  world->require_subcommand(1);

  auto files = std::make_shared<std::vector<std::string>>();
  auto* check = world->add_subcommand("check", "Load world files and report each one's errors");
  check->add_option("files", *files, "World files (YAML)")->required();
  check->callback([files, &run] {
    run = [files] {
      int status = 0;
      for (const auto& file : *files) {
        try {
          const sim::Arena arena = sim::load_arena(file);
          std::cout << file << ": ok, " << describe(arena) << '\n';
        } catch (const config::ConfigError& e) {
          std::cout << e.what() << '\n';
          status = 1;
        }
      }
      return status;
    };
  });

  struct RenderArgs {
    std::string file;
    std::string out;
    std::string title;
    double scale = 200;
  };
  auto render_args = std::make_shared<RenderArgs>();
  auto* render =
      world->add_subcommand("render", "Draw a world as SVG (the built-in warehouse when no file)");
  render->add_option("file", render_args->file, "World file (YAML)");
  render->add_option("-o,--out", render_args->out, "Write the SVG here instead of to stdout");
  render->add_option("--title", render_args->title,
                     "Title above the drawing (default: the world's name)");
  render->add_option("--scale", render_args->scale, "Pixels per metre")
      ->check(CLI::Range(10.0, 2000.0));
  render->callback([render_args, &run] {
    run = [render_args] {
      try {
        const sim::Arena arena = arena_from(render_args->file);
        sim::SvgOptions options;
        options.title = render_args->title.empty() ? arena.name : render_args->title;
        options.pixels_per_m = render_args->scale;
        const std::string svg = sim::render_svg(arena, {}, options);
        if (render_args->out.empty()) {
          std::cout << svg;
          return 0;
        }
        std::ofstream out(render_args->out, std::ios::binary);
        out << svg;
        out.close();
        if (!out) {
          std::cerr << "hil world render: cannot write " << render_args->out << '\n';
          return 1;
        }
        std::cout << "wrote " << render_args->out << " (" << describe(arena) << ")\n";
        return 0;
      } catch (const config::ConfigError& e) {
        std::cerr << e.what() << '\n';
        return 1;
      }
    };
  });

  auto* print = world->add_subcommand(
      "default", "Print the built-in warehouse as a world file, to start your own from");
  print->callback([&run] {
    run = [] {
      std::cout << sim::to_yaml(sim::default_warehouse_arena());
      return 0;
    };
  });
}

}  // namespace hil::apps

// hil profiles [CAR]: every car's named dialects with their sources.

#include <CLI/CLI.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <string_view>

#include "apps/hil/cli_common.hpp"
#include "link/time.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps {
namespace {

constexpr std::size_t kLineWidth = 100;

/// `label` and `text` after `indent`, folded at spaces so that no line
/// passes kLineWidth unless one word does; later lines start where the text
/// of the first does.
void print_folded(std::ostream& out, std::string_view indent, std::string_view label,
                  std::string_view text) {
  std::string line = std::string(indent) + std::string(label);
  const std::size_t bare = line.size();
  while (!text.empty()) {
    const std::size_t space = text.find(' ');
    const std::string_view word = text.substr(0, space);
    if (line.size() > bare && line.size() + 1 + word.size() > kLineWidth) {
      out << line << '\n';
      line = std::string(bare, ' ');
    } else if (line.size() > bare) {
      line += ' ';
    }
    line += word;
    text = space == std::string_view::npos ? std::string_view() : text.substr(space + 1);
  }
  out << line << '\n';
}

void print_car(std::ostream& out, std::string_view car) {
  out << car << '\n';
  for (const protocol::CarProfile& p : protocol::car_profiles_of(car)) {
    out << "  " << p.name << (p.is_default ? " (default)" : "") << '\n';
    print_folded(out, "    ", "source: ", p.source);
    print_folded(out, "    ", "", p.summary);
    out << "    reply latency: "
        << link::format_ms(std::chrono::duration_cast<link::Duration>(p.reply_latency))
        << " processing";
    if (p.baud != 0) out << ", then the line at " << p.baud << " baud";
    out << '\n';
    print_folded(out, "      ", "", p.latency_basis);
  }
}

}  // namespace

void register_profiles(CLI::App& app, std::function<int()>& run) {
  auto car = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "profiles", "List each car's profiles: the dialects hil can play, with their sources");
  cmd->add_option("car", *car, "Only this car (logi, wr8, arduino or leka)");
  cmd->callback([car, &run] {
    run = [car] {
      try {
        if (!car->empty()) {
          print_car(std::cout, *car);
          return 0;
        }
        for (const auto c : protocol::car_profile_cars())
          print_car(std::cout, c);
        return 0;
      } catch (const protocol::ProfileError& e) {
        std::cerr << "hil profiles: " << e.what() << '\n';
        return 2;
      }
    };
  });
}

}  // namespace hil::apps

// hil profiles [CAR]: every car's named dialects with their sources.

#include <CLI/CLI.hpp>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>

#include "apps/hil/cli_common.hpp"
#include "link/time.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::apps {
namespace {

void print_car(std::ostream& out, std::string_view car) {
  out << car << '\n';
  for (const protocol::CarProfile& p : protocol::car_profiles_of(car)) {
    out << "  " << p.name << (p.is_default ? " (default)" : "") << '\n'
        << "    source: " << p.source << '\n'
        << "    " << p.summary << '\n'
        << "    reply latency: "
        << link::format_ms(std::chrono::duration_cast<link::Duration>(p.reply_latency))
        << " processing";
    if (p.baud != 0) out << ", then the line at " << p.baud << " baud";
    out << "\n      " << p.latency_basis << '\n';
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

#include "harness/emulated_car.hpp"

#include <string_view>
#include <variant>
#include <vector>

#include "base/duration.hpp"

namespace hil::harness {

bool acts_on_emulated_board(const mocks::Action& action) {
  return std::holds_alternative<mocks::SendBytes>(action) ||
         std::holds_alternative<mocks::CloseConnection>(action);
}

std::string behaviour_phrase(const mocks::Action& action) {
  const std::string name(mocks::action_name(action));
  const bool vowel =
      !name.empty() && std::string_view("aeiou").find(name[0]) != std::string_view::npos;
  return std::string(vowel ? "an `" : "a `") + name + "` behaviour";
}

std::optional<UnplayableStep> first_unplayable_step(const Scenario& scenario) {
  const auto find = [](const char* list, const char* prefix,
                       const auto& steps) -> std::optional<UnplayableStep> {
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const Step& step = steps[i];
      const auto* car = std::get_if<CarStep>(&step.action);
      if (car == nullptr || acts_on_emulated_board(car->behaviour.action)) continue;
      return UnplayableStep{list, prefix, i, &step, &car->behaviour.action};
    }
    return std::nullopt;
  };
  if (auto u = find("setup", "setup step ", scenario.setup)) return u;
  if (auto u = find("steps", "step ", scenario.steps)) return u;
  if (auto u = find("teardown", "teardown step ", scenario.teardown)) return u;
  std::vector<Step> scheduled;
  for (const auto& s : scenario.schedule)
    scheduled.push_back(s.step);
  if (auto u = find("schedule", "schedule ", scheduled)) {
    u->step = &scenario.schedule[u->index].step;
    u->action = &std::get<CarStep>(u->step->action).behaviour.action;
    return u;
  }
  return std::nullopt;
}

std::optional<std::string> emulated_board_problem(const Scenario& scenario) {
  if (const auto u = first_unplayable_step(scenario)) {
    return "it arms " + behaviour_phrase(*u->action) + " (" + u->prefix +
           std::to_string(u->index + 1) + ", line " + std::to_string(u->step->line) +
           "), which needs the behavioural mock";
  }
  if (scenario.reply_latency) {
    return "it sets reply_latency: " + duration_literal(*scenario.reply_latency) +
           ", which the emulated board does not take (its answers take the chip's own time)";
  }
  return std::nullopt;
}

}  // namespace hil::harness

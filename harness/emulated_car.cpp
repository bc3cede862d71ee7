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

namespace {

// "it arms a `reject` behaviour (step 2, line 27), ..." for the first step
// of `steps` whose behaviour the board cannot act on.
std::optional<std::string> behaviour_problem(const std::vector<Step>& steps,
                                             const std::string& prefix) {
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const auto* car = std::get_if<CarStep>(&steps[i].action);
    if (car == nullptr || acts_on_emulated_board(car->behaviour.action)) continue;
    return "it arms " + behaviour_phrase(car->behaviour.action) + " (" + prefix +
           std::to_string(i + 1) + ", line " + std::to_string(steps[i].line) +
           "), which needs the behavioural mock";
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> emulated_board_problem(const Scenario& scenario) {
  if (auto why = behaviour_problem(scenario.setup, "setup step ")) return why;
  if (auto why = behaviour_problem(scenario.steps, "step ")) return why;
  if (auto why = behaviour_problem(scenario.teardown, "teardown step ")) return why;
  std::vector<Step> scheduled;
  for (const auto& s : scenario.schedule)
    scheduled.push_back(s.step);
  if (auto why = behaviour_problem(scheduled, "schedule ")) return why;
  if (scenario.reply_latency) {
    return "it sets reply_latency: " + duration_literal(*scenario.reply_latency) +
           ", which the emulated board does not take (its answers take the chip's own time)";
  }
  return std::nullopt;
}

}  // namespace hil::harness

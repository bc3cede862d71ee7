// The profile registry: every car has exactly one default, names are unique
// per car, and a wrong name is refused with the valid ones.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "protocol/common/car_profile.hpp"

namespace hil::protocol {
namespace {

TEST(CarProfiles, EveryCarHasExactlyOneDefaultAndUniqueNames) {
  const auto cars = car_profile_cars();
  EXPECT_EQ(cars, (std::vector<std::string_view>{"logi", "wr8", "arduino", "leka"}));
  for (const auto car : cars) {
    std::set<std::string_view> names;
    int defaults = 0;
    for (const CarProfile& p : car_profiles_of(car)) {
      EXPECT_TRUE(names.insert(p.name).second) << car << " " << p.name;
      EXPECT_FALSE(p.source.empty()) << p.name;
      EXPECT_FALSE(p.summary.empty()) << p.name;
      defaults += p.is_default ? 1 : 0;
    }
    EXPECT_EQ(defaults, 1) << car;
    EXPECT_TRUE(car_profiles_of(car).front().is_default) << car;
  }
}

TEST(CarProfiles, TheDefaultsAreTheBoardPeopleOwnAndTheReadme) {
  EXPECT_EQ(default_car_profile("arduino").name, "firmware");
  EXPECT_EQ(default_car_profile("leka").name, "readme");
  EXPECT_EQ(default_car_profile("logi").name, "guide");
  EXPECT_EQ(find_car_profile("arduino", "").name, "firmware");
  EXPECT_EQ(find_car_profile("arduino", "readme").car, "arduino");
}

TEST(CarProfiles, Wr8HasTheDocumentAndBothRealProgramsOnTheirOwnPort) {
  EXPECT_EQ(default_car_profile("wr8").name, "document");
  EXPECT_EQ(car_profile_names("wr8"), "document (the default), svgui-2019 and svgui-head");
  EXPECT_EQ(default_car_profile("wr8").tcp_port, 0);  // hil's own port, 9100
  for (const std::string_view name : {"svgui-2019", "svgui-head"}) {
    const CarProfile& p = find_car_profile("wr8", name);
    EXPECT_EQ(p.tcp_port, 5556) << name;  // the programs' test car listens there
    EXPECT_EQ(p.baud, 0u) << name;
    EXPECT_NE(p.source.find("smart_vehicle_gui"), std::string_view::npos) << name;
  }
  EXPECT_NE(find_car_profile("wr8", "svgui-2019").source.find("8d80e92"), std::string_view::npos);
  EXPECT_NE(find_car_profile("wr8", "svgui-head").source.find("431e8d4"), std::string_view::npos);
}

TEST(CarProfiles, AWrongNameIsRefusedWithTheValidOnes) {
  try {
    find_car_profile("arduino", "firmwar");
    FAIL() << "no error";
  } catch (const ProfileError& e) {
    EXPECT_STREQ(e.what(),
                 "arduino has no profile 'firmwar'; its profiles are firmware (the default) and "
                 "readme");
  }
  EXPECT_EQ(car_profile_problem("arduino", "firmware"), "");
  EXPECT_EQ(car_profile_problem("arduino", ""), "");
  EXPECT_EQ(car_profile_problem("leka", "firmware"),
            "leka has no profile 'firmware'; its profiles are readme (the default) and "
            "comspecs-v3");
  try {
    find_car_profile("tank", "firmware");
    FAIL() << "no error";
  } catch (const ProfileError& e) {
    EXPECT_STREQ(e.what(), "unknown car 'tank'; the cars are logi, wr8, arduino and leka");
  }
  EXPECT_THROW(car_profiles_of("tank"), ProfileError);
  EXPECT_EQ(car_profile_names("leka"), "readme (the default) and comspecs-v3");
  EXPECT_EQ(car_profile_names("arduino"), "firmware (the default) and readme");
}

}  // namespace
}  // namespace hil::protocol

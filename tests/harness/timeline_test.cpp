// The timeline keeps records in arrival order and writes them as NDJSON
// with the time, source and kind first.

#include <gtest/gtest.h>

#include "harness/timeline.hpp"

namespace hil::harness {
namespace {

TEST(Timeline, WritesOneOrderedJsonObjectPerRecord) {
  Timeline t;
  t.add(Time(link::milliseconds(1500)), Source::wire, "frame",
        {{"dir", "to_car"}, {"stage", "delivered"}, {"frame", "MV:STOP"}});
  t.add(Time(link::milliseconds(1500)), Source::client, "stale");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.records()[1].kind, "stale");
  EXPECT_EQ(t.to_ndjson(),
            "{\"t_ms\":1500.0,\"source\":\"wire\",\"kind\":\"frame\",\"dir\":\"to_car\","
            "\"frame\":\"MV:STOP\",\"stage\":\"delivered\"}\n"
            "{\"t_ms\":1500.0,\"source\":\"client\",\"kind\":\"stale\"}\n");
}

}  // namespace
}  // namespace hil::harness

// The Prometheus text exposition format (0.0.4) a scraper reads from
// GET /metrics: HELP and TYPE lines, escaped label values, and numbers
// spelled as Prometheus spells them.
#include "base/prometheus_text.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace hil::base {
namespace {

TEST(PrometheusText, WritesHelpTypeAndOneLinePerSample) {
  MetricFamily bytes{"hil_proxy_bytes_total", "Bytes delivered.", MetricFamily::Type::counter, {}};
  bytes.add({{"route", "car"}, {"direction", "to_car"}}, 120)
      .add({{"route", "car"}, {"direction", "to_client"}}, 3400);
  MetricFamily open{"hil_proxy_open_links", "Links open now.", MetricFamily::Type::gauge, {}};
  open.add({{"route", "car"}}, 2);
  EXPECT_EQ(prometheus_text({bytes, open}),
            "# HELP hil_proxy_bytes_total Bytes delivered.\n"
            "# TYPE hil_proxy_bytes_total counter\n"
            "hil_proxy_bytes_total{route=\"car\",direction=\"to_car\"} 120\n"
            "hil_proxy_bytes_total{route=\"car\",direction=\"to_client\"} 3400\n"
            "# HELP hil_proxy_open_links Links open now.\n"
            "# TYPE hil_proxy_open_links gauge\n"
            "hil_proxy_open_links{route=\"car\"} 2\n");
}

TEST(PrometheusText, AFamilyWithoutSamplesStillHasItsHeader) {
  EXPECT_EQ(
      prometheus_text({MetricFamily{"up", "Whether it is up.", MetricFamily::Type::gauge, {}}}),
      "# HELP up Whether it is up.\n# TYPE up gauge\n");
}

TEST(PrometheusText, ASampleWithoutLabelsHasNoBraces) {
  MetricFamily family{"hil_requests_total", "Requests.", MetricFamily::Type::counter, {}};
  family.add({}, 7);
  EXPECT_EQ(prometheus_text({family}),
            "# HELP hil_requests_total Requests.\n# TYPE hil_requests_total counter\n"
            "hil_requests_total 7\n");
}

TEST(PrometheusText, EscapesBackslashQuoteAndNewlineInLabelValues) {
  MetricFamily family{"m", "h", MetricFamily::Type::gauge, {}};
  family.add({{"path", "C:\\cars\\\"one\"\nnext"}}, 1);
  EXPECT_EQ(prometheus_text({family}),
            "# HELP m h\n# TYPE m gauge\nm{path=\"C:\\\\cars\\\\\\\"one\\\"\\nnext\"} 1\n");
}

TEST(PrometheusText, EscapesBackslashAndNewlineInHelpButNotQuotes) {
  MetricFamily family{"m", "a \"b\" \\ c\nd", MetricFamily::Type::gauge, {}};
  EXPECT_EQ(prometheus_text({family}), "# HELP m a \"b\" \\\\ c\\nd\n# TYPE m gauge\n");
}

TEST(PrometheusText, SpellsNumbersAsPrometheusDoes) {
  MetricFamily family{"m", "h", MetricFamily::Type::gauge, {}};
  family.add({{"v", "int"}}, 42)
      .add({{"v", "zero"}}, 0)
      .add({{"v", "negative"}}, -3)
      .add({{"v", "big"}}, 123456789012.0)
      .add({{"v", "fraction"}}, 0.25)
      .add({{"v", "third"}}, 1.0 / 3.0)
      .add({{"v", "inf"}}, std::numeric_limits<double>::infinity())
      .add({{"v", "-inf"}}, -std::numeric_limits<double>::infinity())
      .add({{"v", "nan"}}, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(prometheus_text({family}),
            "# HELP m h\n# TYPE m gauge\n"
            "m{v=\"int\"} 42\n"
            "m{v=\"zero\"} 0\n"
            "m{v=\"negative\"} -3\n"
            "m{v=\"big\"} 123456789012\n"
            "m{v=\"fraction\"} 0.25\n"
            "m{v=\"third\"} 0.3333333333333333\n"
            "m{v=\"inf\"} +Inf\n"
            "m{v=\"-inf\"} -Inf\n"
            "m{v=\"nan\"} NaN\n");
}

TEST(PrometheusText, RefusesNamesPrometheusWouldRefuse) {
  EXPECT_THROW(prometheus_text({MetricFamily{"9lives", "h", MetricFamily::Type::gauge, {}}}),
               std::invalid_argument);
  EXPECT_THROW(prometheus_text({MetricFamily{"", "h", MetricFamily::Type::gauge, {}}}),
               std::invalid_argument);
  EXPECT_THROW(prometheus_text({MetricFamily{"has-dash", "h", MetricFamily::Type::gauge, {}}}),
               std::invalid_argument);
  MetricFamily bad_label{"ok:name_1", "h", MetricFamily::Type::gauge, {}};
  bad_label.add({{"bad:label", "x"}}, 1);
  EXPECT_THROW(prometheus_text({bad_label}), std::invalid_argument);
  MetricFamily reserved{"ok", "h", MetricFamily::Type::gauge, {}};
  reserved.add({{"__name__", "x"}}, 1);
  EXPECT_THROW(prometheus_text({reserved}), std::invalid_argument);
  MetricFamily good{"ok:name_1", "h", MetricFamily::Type::gauge, {}};
  good.add({{"_label9", "x"}}, 1);
  EXPECT_NO_THROW(prometheus_text({good}));
}

}  // namespace
}  // namespace hil::base

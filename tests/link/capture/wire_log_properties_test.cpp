#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>

#include "link/capture/wire_log.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/link/capture/capture_support.hpp"
#include "tests/protocol/logi/logi_generators.hpp"

namespace hil::link {
namespace {

using protocol::Bytes;

bool all_text(const Bytes& bytes) {
  return std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t b) {
    return (b >= 0x20 && b < 0x7F) || b == '\t' || b == '\r' || b == '\n';
  });
}

struct FrameSummary {
  std::string kind;
  bool valid;
  std::string text;
  friend bool operator==(const FrameSummary&, const FrameSummary&) = default;
};

void collect(const nlohmann::json& frames, std::vector<FrameSummary>& out) {
  for (const auto& f : frames)
    out.push_back({f["kind"], f["valid"], f["text"]});
}

RC_GTEST_PROP(WireLogProperties, BytesSurviveTheLogExactly, (const Bytes& bytes)) {
  nlohmann::json record;
  put_bytes(record, bytes);
  // Through text, as a reader of the file sees it.
  const auto back = nlohmann::json::parse(record.dump());
  RC_ASSERT(bytes_of(back) == bytes);
  RC_ASSERT(back["bytes"].get<std::size_t>() == bytes.size());
  RC_ASSERT(back.contains("text") == all_text(bytes));
  RC_ASSERT(back.contains("hex") != all_text(bytes));
}

// However a LOGI stream (with garbage between frames) is cut into
// deliveries, the log holds every byte once, in order, and the frames it
// lists are the frames of the whole stream.
RC_GTEST_PROP(WireLogProperties, AnyChunkingGivesTheSameBytesAndFrames,
              (const std::vector<protocol::logi::Message>& messages)) {
  Bytes stream;
  for (const auto& m : messages) {
    if (*rc::gen::inRange(0, 5) == 0) {
      const auto garbage = *rc::gen::container<Bytes>(*rc::gen::inRange<std::size_t>(1, 6),
                                                      rc::gen::arbitrary<std::uint8_t>());
      stream.insert(stream.end(), garbage.begin(), garbage.end());
    }
    const auto frame = protocol::logi::encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  const auto cuts =
      *rc::gen::container<std::vector<std::size_t>>(rc::gen::inRange<std::size_t>(1, 40));

  test::ScratchFile file(".ndjson");
  std::error_code ec;
  WireLogOptions options;
  options.protocol = protocol_adapter("logi");
  auto log = WireLog::open(file.path(), options, ec);
  RC_ASSERT(log != nullptr);
  std::size_t pos = 0;
  std::size_t i = 0;
  std::int64_t t_us = 0;
  while (pos < stream.size()) {
    const std::size_t n =
        std::min(cuts.empty() ? stream.size() : cuts[i++ % cuts.size()], stream.size() - pos);
    log->on_delivered(microseconds(t_us += 250), Direction::to_client,
                      protocol::ByteView(stream).subspan(pos, n));
    pos += n;
  }
  log->on_close(microseconds(t_us + 1), {LinkClose::By::car, CloseMode::graceful, "car closed"});

  std::vector<WireFrame> expected_frames;
  auto splitter = options.protocol->splitter();
  splitter->feed(stream, expected_frames);
  splitter->finish(expected_frames);
  std::vector<FrameSummary> expected;
  for (const auto& f : expected_frames)
    expected.push_back({f.kind, f.valid, f.text});

  Bytes logged;
  std::vector<FrameSummary> frames;
  double last_t_ms = -1;
  for (const auto& r : read_wire_log(file.path())) {
    RC_ASSERT(r["t_ms"].get<double>() > last_t_ms);
    last_t_ms = r["t_ms"].get<double>();
    if (r["event"] == "delivered") {
      const auto b = bytes_of(r);
      logged.insert(logged.end(), b.begin(), b.end());
      collect(r["frames"], frames);
    } else if (r.contains("unfinished")) {
      for (const auto& u : r["unfinished"])
        collect(u["frames"], frames);
    }
  }
  RC_ASSERT(logged == stream);
  RC_ASSERT(frames == expected);
}

}  // namespace
}  // namespace hil::link

// PipeBinding, the I/O half of every client session, on mem:// in virtual
// time: what it reports, what it stops reporting once a pipe is replaced
// or the binding is gone, and its one timer.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "client/common/pipe_binding.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"

namespace hil::client {
namespace {

using link::milliseconds;

std::string text(protocol::ByteView bytes) {
  return {bytes.begin(), bytes.end()};
}

protocol::ByteView view(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

struct PipeBindingOnMem : ::testing::Test {
  PipeBindingOnMem() {
    listener = link::listen(context, link::MemEndpoint{"car"});
    listener->start([this](link::BytePipePtr pipe) {
      peers.push_back(pipe);
      pipe->start({[this](protocol::ByteView bytes) { received += text(bytes); }, {}});
    });
  }

  std::unique_ptr<PipeBinding> make(link::Endpoint endpoint = link::MemEndpoint{"car"}) {
    return std::make_unique<PipeBinding>(
        context, std::move(endpoint),
        PipeBinding::Handlers{
            .connected = [this] { reports.push_back("connected"); },
            .connect_failed = [this](std::error_code) { reports.push_back("failed"); },
            .bytes = [this](protocol::ByteView b) { reports.push_back("bytes " + text(b)); },
            .closed = [this] { reports.push_back("closed"); },
            .timer = [this] { reports.push_back("timer at " + std::to_string(now_ms())); }});
  }

  std::int64_t now_ms() const { return executor.now().count() / 1'000'000; }

  link::VirtualExecutor executor;
  link::TransportContext context{executor};
  std::unique_ptr<link::Listener> listener;
  std::vector<link::BytePipePtr> peers;
  std::vector<std::string> reports;
  std::string received;
};

TEST_F(PipeBindingOnMem, ConnectsWritesAndReportsWhatThePeerSendsAndItsClose) {
  auto binding = make();
  EXPECT_FALSE(binding->write(view("early")));  // no pipe yet: nothing is written
  binding->open();
  executor.run_for(milliseconds(0));
  ASSERT_EQ(reports, std::vector<std::string>{"connected"});
  ASSERT_TRUE(binding->has_pipe());
  EXPECT_TRUE(binding->write(view("hello")));
  ASSERT_EQ(peers.size(), 1u);
  peers[0]->write(view("world"));
  executor.run_for(milliseconds(0));
  EXPECT_EQ(received, "hello");
  peers[0]->close();
  executor.run_for(milliseconds(0));
  EXPECT_EQ(reports, (std::vector<std::string>{"connected", "bytes world", "closed"}));
  EXPECT_FALSE(binding->has_pipe());
}

TEST_F(PipeBindingOnMem, AFailedConnectIsReported) {
  auto binding = make(link::MemEndpoint{"nobody"});
  binding->open();
  executor.run_for(milliseconds(0));
  EXPECT_EQ(reports, std::vector<std::string>{"failed"});
  EXPECT_FALSE(binding->has_pipe());
}

TEST_F(PipeBindingOnMem, NothingIsReportedAboutAPipeClosedHereOrReplaced) {
  auto binding = make();
  binding->open();
  executor.run_for(milliseconds(0));
  binding->close();
  peers[0]->write(view("late"));
  executor.run_for(milliseconds(0));
  EXPECT_EQ(reports, std::vector<std::string>{"connected"});

  binding->open();  // a new pipe; then open again before it is used
  binding->open();
  executor.run_for(milliseconds(0));
  EXPECT_EQ(reports, (std::vector<std::string>{"connected", "connected"}));
  ASSERT_EQ(peers.size(), 3u);
  peers[1]->write(view("stale"));
  peers[2]->write(view("fresh"));
  executor.run_for(milliseconds(0));
  EXPECT_EQ(reports.back(), "bytes fresh");
}

TEST_F(PipeBindingOnMem, KeepsOneTimerAndRearmsOnlyWhenTheTimeChanges) {
  auto binding = make();
  binding->schedule(link::Time(milliseconds(300)));
  binding->schedule(link::Time(milliseconds(300)));
  binding->schedule(link::Time(milliseconds(200)));  // moved earlier: fires once, at 200
  executor.run_for(milliseconds(1000));
  EXPECT_EQ(reports, std::vector<std::string>{"timer at 200"});

  binding->schedule(link::Time(milliseconds(1500)));
  binding->schedule(std::nullopt);  // cancelled
  executor.run_for(milliseconds(1000));
  EXPECT_EQ(reports.size(), 1u);
}

TEST_F(PipeBindingOnMem, ReportsNothingOnceDestroyed) {
  auto binding = make();
  binding->open();
  executor.run_for(milliseconds(0));
  binding->schedule(link::Time(milliseconds(100)));
  binding.reset();  // the peer sees the close; no timer or bytes come back
  executor.run_for(milliseconds(500));
  EXPECT_EQ(reports, std::vector<std::string>{"connected"});
  ASSERT_EQ(peers.size(), 1u);
  EXPECT_FALSE(peers[0]->is_open());
}

}  // namespace
}  // namespace hil::client

#pragma once
// The client a scenario drives, whichever it is: hil's reference client of
// the car (harness/reference_client.hpp) or a program under test
// (harness/exec_client.hpp). The step sequencer hands it operator actions
// one at a time and hears how each ended; the run stops it at the end.

#include <functional>
#include <memory>
#include <string>
#include <utility>

namespace hil::harness {

class ScenarioClient {
 public:
  /// How an action ended; `reason` says why it failed (or what came back).
  using Done = std::function<void(bool ok, const std::string& reason)>;

  virtual ~ScenarioClient() = default;

  /// Opens the port for cars whose vocabulary has no `connect` (Arduino,
  /// Leka); nothing for the others.
  virtual void start() {}
  /// Carries out one operator action; `done` runs once when it ends, on a
  /// later executor turn or at once.
  virtual void execute(const std::string& text, Done done) = 0;
  /// Whether execute() may be called again before an earlier action
  /// ended (a scheduled action beside the sequence's); otherwise the
  /// runner hands actions over one at a time.
  virtual bool concurrent() const { return false; }
  /// Abandons the actions under way; their `done` is not called.
  virtual void cancel() = 0;
  /// Closes the connection at the end of the run (no reconnect).
  virtual void stop() = 0;
  /// State that only shows by looking (the Leka port being open), checked
  /// on every simulation tick.
  virtual void poll() {}
  /// After stop(): whether the client is gone for good (an external
  /// program has exited). The runner waits for this a while.
  virtual bool finished() const { return true; }
  /// After stop(), when finished() did not come in time: end it by force
  /// (`hard`: no more chances).
  virtual void terminate(bool hard) { (void)hard; }
  /// `f` runs when an external program prints its first result line (one
  /// of the marks of the run's origin, harness/origin.hpp); a reference
  /// client has no result lines.
  virtual void on_first_result(std::function<void()> f) { (void)f; }
};

/// A client that is another one in every way but what a subclass changes:
/// the base of a test's decorator (one that walks away at the end, one that
/// is stopped when it spins).
class ForwardingClient : public ScenarioClient {
 public:
  explicit ForwardingClient(std::unique_ptr<ScenarioClient> inner) : inner_(std::move(inner)) {}

  void start() override { inner_->start(); }
  void execute(const std::string& text, Done done) override {
    inner_->execute(text, std::move(done));
  }
  bool concurrent() const override { return inner_->concurrent(); }
  void cancel() override { inner_->cancel(); }
  void stop() override { inner_->stop(); }
  void poll() override { inner_->poll(); }
  bool finished() const override { return inner_->finished(); }
  void terminate(bool hard) override { inner_->terminate(hard); }
  void on_first_result(std::function<void()> f) override { inner_->on_first_result(std::move(f)); }

 protected:
  ScenarioClient& inner() { return *inner_; }

 private:
  std::unique_ptr<ScenarioClient> inner_;
};

}  // namespace hil::harness

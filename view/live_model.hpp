#pragma once
// What the live view shows of running mock cars and what its control panel
// may do to them: a JSON snapshot of each car's world, sensors, wire and
// faults, and the panel's actions as JSON requests. Everything here runs on
// the thread that runs the cars (see view/server.hpp for the HTTP side).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/prometheus_text.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "link/protocol_adapter.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"

namespace hil::view {

/// Watches every link of one car's server and keeps the last frames in each
/// direction (as delivered, after faults), decoded, and the last faults.
class WireWatch final : public link::LinkObserver {
 public:
  struct Frame {
    link::Time at{};
    bool valid = false;
    std::string kind;
    std::string text;
    std::string hex;
  };
  struct Fault {
    link::Time at{};
    link::Direction direction = link::Direction::to_car;
    std::string kind;
    std::string rule;
    std::string detail;
  };
  static constexpr std::size_t kFramesKept = 16;
  static constexpr std::size_t kFaultsKept = 16;

  explicit WireWatch(std::shared_ptr<const link::ProtocolAdapter> adapter);

  void on_open(link::Time at, const std::string& client, const std::string& car) override;
  void on_delivered(link::Time at, link::Direction d, protocol::ByteView bytes) override;
  void on_fault(const link::FaultEvent& event) override;
  void on_close(link::Time at, const link::LinkClose& close) override;

  const std::deque<Frame>& frames(link::Direction d) const { return frames_[static_cast<int>(d)]; }
  const std::deque<Fault>& faults() const { return faults_; }
  std::uint64_t frames_seen(link::Direction d) const { return seen_[static_cast<int>(d)]; }
  const std::string& last_close() const { return last_close_; }

 private:
  std::shared_ptr<const link::ProtocolAdapter> adapter_;
  std::unique_ptr<link::FrameSplitter> splitters_[2];
  std::deque<Frame> frames_[2];
  std::deque<Fault> faults_;
  std::uint64_t seen_[2] = {0, 0};
  std::string last_close_;
  std::vector<link::WireFrame> scratch_;
};

/// One car as the view sees it; the pointers must outlive the model.
struct ViewedCar {
  mocks::MockCar* car = nullptr;
  mocks::MockServer* server = nullptr;  ///< may be null: no wire, no fault rules
  std::shared_ptr<WireWatch> watch;     ///< may be null: no frames shown
  link::FaultProfile faults;            ///< the rules the server started with
  std::string faults_text;              ///< their source, when known
};

/// The answer to an API request: an HTTP status and a JSON body.
struct Reply {
  int status = 200;
  nlohmann::json body;
};

class LiveModel {
 public:
  static constexpr std::size_t kTrailPoints = 600;

  explicit LiveModel(std::vector<ViewedCar> cars);

  /// Samples the cars (trail); call at the view's update rate.
  void sample();
  /// Everything the page draws, for every car: arena, pose, sensors,
  /// telemetry, mode, frames, faults. `now` is the cars' clock.
  nlohmann::json snapshot(link::Time now) const;

  /// Runs one API request: `action` is the path after /api/ ("faults",
  /// "behaviour", "car", "obstacle", "reset"), `body` the request's JSON
  /// text. Bad requests answer 400 with {"error": "..."}; never throws.
  Reply handle(std::string_view action, std::string_view body);

  /// The cars' counters for GET /metrics, one sample per car (labelled
  /// with its name): hil_mock_bytes_total, hil_mock_frames_total,
  /// hil_mock_bad_frames_total, hil_mock_faults_total (every kind, zeros
  /// included), hil_mock_connections_total, hil_mock_open_connections.
  std::vector<base::MetricFamily> metrics() const;

  std::size_t car_count() const { return cars_.size(); }

 private:
  struct Car {
    ViewedCar viewed;
    std::size_t original_obstacles = 0;
    std::deque<sim::Pose> trail;
  };
  Reply set_faults(Car& car, const nlohmann::json& request);
  Reply trigger(Car& car, const nlohmann::json& request);
  Reply move_car(Car& car, const nlohmann::json& request);
  Reply obstacle(Car& car, const nlohmann::json& request);
  Reply reset(Car& car);
  nlohmann::json car_json(const Car& car, std::size_t index, link::Time now) const;

  std::vector<Car> cars_;
};

}  // namespace hil::view

#pragma once
// The simulated world: an arena turned into Box2D bodies, the vehicles in
// it, and a fixed-step clock (sim/time.hpp) that owns simulated time.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim/arena.hpp"
#include "sim/time.hpp"
#include "sim/vehicle.hpp"

class b2World;
class b2Body;
class b2Fixture;

namespace hil::sim {

struct WorldDef {
  Arena arena = default_warehouse_arena();
  std::uint64_t seed = 1;  ///< seeds sensor noise and sensor faults
  int velocity_iterations = 8;
  int position_iterations = 3;
};

/// A vehicle began or stopped touching something.
struct ContactEvent {
  enum class Phase { begin, end };
  enum class With { wall, obstacle, vehicle };
  Duration time{};
  std::size_t vehicle = 0;  ///< index of the vehicle the event is about
  Phase phase = Phase::begin;
  With with = With::wall;
  std::size_t other = 0;  ///< obstacle or vehicle index (0 for walls)
  std::string other_name;
  Vec2 point_m;  ///< a contact point (begin only; the vehicle's position on end)
};

class World {
 public:
  /// Throws std::invalid_argument naming the problems when the arena is unusable.
  explicit World(WorldDef def);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Adds a car at its start pose (or the arena's).
  Vehicle& add_vehicle(VehicleDef def);
  std::size_t vehicle_count() const { return vehicles_.size(); }
  Vehicle& vehicle(std::size_t index) { return *vehicles_.at(index); }
  const Vehicle& vehicle(std::size_t index) const { return *vehicles_.at(index); }

  /// One fixed step of 1/120 s.
  void step();
  /// Runs every step that ends at or before `time`. Earlier times are ignored.
  void advance_to(Duration time);
  /// Moves the requested time on by `duration` and runs the steps due; many
  /// small advances run the same steps as one large one.
  void advance_by(Duration duration) { advance_to(requested_ + duration); }

  /// End of the last step run.
  Duration time() const { return step_end(steps_); }
  std::int64_t steps() const { return steps_; }

  /// Contact events since the last call, in the order they happened.
  std::vector<ContactEvent> take_contacts();

  /// A hash of everything that decides the future: step count, bodies,
  /// chassis, batteries, odometry, random generators. Equal hashes after
  /// the same inputs are the determinism guarantee.
  std::uint64_t state_hash() const;

  /// Puts an obstacle into the arena while the world runs (a parcel dropped
  /// in a car's path). Returns its index in arena().obstacles. Throws
  /// std::invalid_argument for a shape with no area.
  std::size_t add_obstacle(Obstacle obstacle);
  /// Takes an obstacle out again; false when it is not there. Its entry in
  /// arena().obstacles stays (indices do not move); obstacle_present() says
  /// whether it is in the world.
  bool remove_obstacle(std::size_t index);
  bool obstacle_present(std::size_t index) const;

  const Arena& arena() const { return def_.arena; }
  std::uint64_t seed() const { return def_.seed; }
  b2World& box2d() { return *b2_; }

  /// Distance to the first fixture along from->to, skipping `ignore`.
  std::optional<double> ray_cast(Vec2 from, Vec2 to, const b2Body* ignore) const;

 private:
  friend class Vehicle;
  class ContactListener;
  void build_arena();
  void add_obstacle_fixture(std::size_t index);

  WorldDef def_;
  std::unique_ptr<b2World> b2_;
  std::unique_ptr<ContactListener> listener_;
  b2Body* ground_ = nullptr;                   // walls and obstacles
  std::vector<b2Fixture*> obstacle_fixtures_;  // per arena obstacle; null once removed
  std::vector<std::unique_ptr<Vehicle>> vehicles_;
  std::vector<ContactEvent> contacts_;
  std::int64_t steps_ = 0;
  Duration requested_{};
};

}  // namespace hil::sim

#pragma once
// The callbacks a session keeps for the requests it has queued on its core,
// each run once with its request's result.

#include <functional>
#include <map>
#include <utility>

namespace hil::client {

template <class Id, class Result>
class RequestCallbacks {
 public:
  using Callback = std::function<void(const Result&)>;

  /// Keeps `done` (when it is set) for the request `id`.
  void add(Id id, Callback done) {
    if (done) callbacks_[id] = std::move(done);
  }
  /// Runs and forgets the callback of request `id`, if it has one.
  void complete(Id id, const Result& result) {
    const auto it = callbacks_.find(id);
    if (it == callbacks_.end()) return;
    Callback callback = std::move(it->second);
    callbacks_.erase(it);
    callback(result);
  }

 private:
  std::map<Id, Callback> callbacks_;
};

}  // namespace hil::client

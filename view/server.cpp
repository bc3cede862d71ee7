#include "view/server.hpp"

#include <httplib.h>

#include <asio/post.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "base/prometheus_text.hpp"
#include "view/page.hpp"

namespace hil::view {

// What the HTTP threads and the io thread share, all behind one mutex: the
// latest snapshot as text (the io thread writes it, every event stream
// reads it) and whether the server is stopping.
struct LiveViewServer::Shared {
  std::mutex mutex;
  std::condition_variable changed;
  std::string snapshot = "{\"cars\":[]}";
  std::uint64_t version = 0;
  bool stopping = false;
  std::atomic<int> viewers{0};
  std::atomic<bool> listen_returned{false};
  httplib::Server http;
  std::thread thread;
};

namespace {

constexpr auto kApiWait = std::chrono::seconds(5);
constexpr std::size_t kMaxBodyBytes = 256 * 1024;
constexpr int kHttpThreads = 48;  // every open event stream holds one

void send_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

// Runs `work` on the cars' thread (`io`) and waits for its result; nullopt,
// with `why` for a 503, when the cars stop or do not answer in time. Waits
// in short steps so stop() (which runs on the cars' thread and joins the
// HTTP threads) never waits out the whole limit.
template <class T, class Work>
std::optional<T> ask_cars(asio::io_context& io, Work work, const std::function<bool()>& stopping,
                          std::string& why) {
  auto promise = std::make_shared<std::promise<T>>();
  auto result = promise->get_future();
  asio::post(io, [promise, work = std::move(work)] { promise->set_value(work()); });
  const auto deadline = std::chrono::steady_clock::now() + kApiWait;
  while (result.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
    const bool stop = stopping();
    if (stop || std::chrono::steady_clock::now() > deadline) {
      why = stop ? "the cars are stopping" : "the cars did not answer in time";
      return std::nullopt;
    }
  }
  try {
    return result.get();
  } catch (const std::future_error&) {
    why = "the cars are stopping";
    return std::nullopt;
  }
}

}  // namespace

LiveViewServer::LiveViewServer(asio::io_context& io, link::Executor& executor, LiveModel& model,
                               ViewOptions options)
    : io_(io),
      executor_(executor),
      model_(model),
      options_(std::move(options)),
      shared_(std::make_shared<Shared>()) {}

LiveViewServer::~LiveViewServer() {
  stop();
}

std::string LiveViewServer::url() const {
  return "http://" + options_.host + ":" + std::to_string(port_) + "/";
}

void LiveViewServer::start() {
  auto shared_owner = shared_;
  // The handlers live in shared->http, so they hold a plain pointer: a
  // shared_ptr in them would keep Shared (and them) alive for ever. They run
  // only inside listen_after_bind, on the thread below, which owns Shared.
  Shared* const shared = shared_owner.get();
  auto& http = shared->http;
  http.new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  http.set_keep_alive_timeout(2);
  http.set_payload_max_length(kMaxBodyBytes);

  http.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(live_view_page()), "text/html; charset=utf-8");
  });
  http.Get("/api/state", [shared](const httplib::Request&, httplib::Response& res) {
    std::lock_guard lock(shared->mutex);
    res.set_header("Cache-Control", "no-store");
    res.set_content(shared->snapshot, "application/json");
  });
  http.Get("/events", [shared](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    ++shared->viewers;
    auto seen = std::make_shared<std::uint64_t>(0);
    res.set_chunked_content_provider(
        "text/event-stream",
        [shared, seen](std::size_t, httplib::DataSink& sink) {
          std::string chunk;
          {
            std::unique_lock lock(shared->mutex);
            shared->changed.wait_for(lock, std::chrono::milliseconds(500),
                                     [&] { return shared->stopping || shared->version != *seen; });
            if (shared->stopping) return false;
            if (shared->version == *seen) {
              chunk = ": idle\n\n";  // a comment line: finds a viewer that went away
            } else {
              *seen = shared->version;
              chunk = "data: " + shared->snapshot + "\n\n";
            }
          }
          return sink.write(chunk.data(), chunk.size());
        },
        [shared](bool) { --shared->viewers; });
  });
  // Whether the server is stopping, for a handler that waits for the cars.
  const std::function<bool()> stopping = [shared] {
    std::lock_guard lock(shared->mutex);
    return shared->stopping;
  };
  // Every action runs on the cars' thread; this thread waits for its reply.
  http.Post(R"(/api/(\w+))", [this, stopping](const httplib::Request& req, httplib::Response& res) {
    std::string why;
    const auto reply = ask_cars<Reply>(
        io_,
        [this, action = req.matches[1].str(), body = req.body] {
          return model_.handle(action, body);
        },
        stopping, why);
    if (!reply) {
      send_json(res, 503, {{"error", why}});
      return;
    }
    send_json(res, reply->status, reply->body);
  });
  // The counters are read on the cars' thread and written out here.
  http.Get("/metrics", [this, stopping](const httplib::Request&, httplib::Response& res) {
    std::string why;
    const auto families = ask_cars<std::vector<base::MetricFamily>>(
        io_, [this] { return model_.metrics(); }, stopping, why);
    res.set_header("Cache-Control", "no-store");
    if (!families) {
      res.status = 503;
      res.set_content(why + "\n", "text/plain; charset=utf-8");
      return;
    }
    try {
      res.set_content(base::prometheus_text(*families), base::kPrometheusContentType);
    } catch (const std::exception& e) {
      res.status = 500;
      res.set_content(std::string("cannot write the metrics: ") + e.what() + "\n",
                      "text/plain; charset=utf-8");
    }
  });
  http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.status == 404) {
      send_json(res, 404, {{"error", "nothing at " + req.path + " (see docs/live-view.md)"}});
    } else if (res.body.empty()) {
      send_json(res, res.status,
                {{"error", "bad request (HTTP " + std::to_string(res.status) +
                               "): a POST needs a JSON body, {} at least"}});
    }
  });

  if (options_.port == 0) {
    const int port = http.bind_to_any_port(options_.host);
    if (port <= 0) throw std::runtime_error("cannot bind " + options_.host);
    port_ = static_cast<std::uint16_t>(port);
  } else {
    if (!http.bind_to_port(options_.host, options_.port))
      throw std::runtime_error("cannot bind " + options_.host + ":" +
                               std::to_string(options_.port) + " (in use?)");
    port_ = options_.port;
  }
  running_ = true;
  refresh();
  shared->thread = std::thread([shared_owner] {
    shared_owner->http.listen_after_bind();
    shared_owner->listen_returned = true;
  });
}

void LiveViewServer::refresh() {
  if (!running_) return;
  model_.sample();
  auto snapshot = model_.snapshot(executor_.now());
  snapshot["viewers"] = shared_->viewers.load();
  snapshot["updates_per_s"] = options_.updates_per_s;
  std::string text = snapshot.dump();
  {
    std::lock_guard lock(shared_->mutex);
    shared_->snapshot = std::move(text);
    ++shared_->version;
  }
  shared_->changed.notify_all();
  timer_ = executor_.call_after(link::milliseconds(1000 / std::max(1, options_.updates_per_s)),
                                [this] { refresh(); });
}

void LiveViewServer::stop() {
  if (!running_) return;
  running_ = false;
  if (timer_ != 0) executor_.cancel(timer_);
  {
    std::lock_guard lock(shared_->mutex);
    shared_->stopping = true;
  }
  shared_->changed.notify_all();
  // httplib's stop() does nothing before its accept loop runs, and the loop
  // would then wait for a connection for ever: a Ctrl-C right after start-up
  // must find the loop running (or already ended) before stopping it.
  while (!shared_->http.is_running() && !shared_->listen_returned)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  shared_->http.stop();
  if (shared_->thread.joinable()) shared_->thread.join();
}

}  // namespace hil::view

#include "control/api_server.hpp"

#include <httplib.h>
#include <sys/socket.h>

#include <asio/post.hpp>

#include <algorithm>
#include <atomic>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

namespace hil::control {

namespace {

// How long an HTTP thread waits for the proxies' thread to answer.
constexpr auto kAnswerWait = std::chrono::seconds(5);

void send(httplib::Response& res, const ApiReply& reply) {
  res.status = reply.status;
  for (const auto& [name, value] : reply.headers)
    res.set_header(name, value);
  if (reply.status != 204) res.set_content(reply.body, reply.content_type);
}

// The raw path of the request line, before '?', still percent-encoded.
std::string raw_path(const httplib::Request& req) {
  const std::string& target = req.target.empty() ? req.path : req.target;
  return target.substr(0, target.find('?'));
}

}  // namespace

RequestRateLimit::RequestRateLimit(int per_second, int burst)
    : per_second_(std::max(1, per_second)),
      burst_(std::max(1, burst)),
      tokens_(std::max(1, burst)) {}

bool RequestRateLimit::allow(std::chrono::nanoseconds now) {
  if (last_ && now > *last_) {
    const double elapsed_s = std::chrono::duration<double>(now - *last_).count();
    tokens_ = std::min(burst_, tokens_ + elapsed_s * per_second_);
  }
  if (!last_ || now > *last_) last_ = now;
  if (tokens_ < 1.0) return false;
  tokens_ -= 1.0;
  return true;
}

bool is_loopback_host(const std::string& host) {
  if (host == "localhost" || host == "::1" || host == "[::1]") return true;
  // 127.0.0.0/8, written as four decimal parts.
  if (!host.starts_with("127.")) return false;
  int parts = 0;
  std::size_t start = 0;
  while (start <= host.size()) {
    const auto dot = host.find('.', start);
    const std::string part = host.substr(start, dot == std::string::npos ? dot : dot - start);
    if (part.empty() || part.size() > 3 ||
        !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
        std::stoi(part) > 255)
      return false;
    ++parts;
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts == 4;
}

// What the HTTP threads share with the server: the rate limit behind its
// mutex, whether the server is stopping, and httplib's server itself.
struct ApiServer::State {
  std::mutex mutex;
  RequestRateLimit rate{kApiRequestsPerSecond, kApiBurst};
  bool stopping = false;
  std::atomic<bool> listen_returned{false};
  httplib::Server http;
  std::thread thread;
  std::uint16_t port = 0;
  bool running = false;
};

ApiServer::ApiServer(asio::io_context& io, ProxyHub& hub, ApiServerOptions options)
    : io_(io), hub_(hub), options_(std::move(options)), state_(std::make_shared<State>()) {
  state_->rate = RequestRateLimit(options_.requests_per_second, options_.burst);
}

ApiServer::~ApiServer() {
  stop();
}

std::uint16_t ApiServer::port() const {
  return state_->port;
}

std::string ApiServer::url() const {
  const bool v6 = options_.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + options_.host + "]" : options_.host) + ":" +
         std::to_string(state_->port);
}

void ApiServer::start() {
  // The handlers live in state->http and run only on its threads, which
  // stop() joins: a plain pointer does.
  State* const state = state_.get();
  auto& http = state->http;
  // Requests answered side by side: clients that connect and send nothing
  // (or half a request) each hold one thread until the read timeout, so
  // a few dozen of them do not keep a test's requests waiting.
  http.new_task_queue = [] { return new httplib::ThreadPool(kApiThreads); };
  http.set_keep_alive_timeout(2);
  // A client that sends half a request holds one of httplib's threads this
  // long at most.
  http.set_read_timeout(2, 0);
  http.set_write_timeout(5, 0);
  http.set_payload_max_length(kMaxApiBodyBytes);
  // httplib's default adds SO_REUSEPORT, with which a second hil proxy on
  // the same --api port would share it instead of being told it is in use.
  http.set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });

  const std::string too_many =
      "requests: more than " + std::to_string(options_.requests_per_second) +
      " a second (bursts of " + std::to_string(options_.burst) + "); retry in a second";
  http.set_pre_routing_handler(
      [state, too_many](const httplib::Request& req, httplib::Response& res) {
        // A web page the user has open may send requests to 127.0.0.1 from
        // their browser; a browser's requests are refused, as Toxiproxy
        // refuses them, so no page can cut a link. Test code, curl and the
        // client libraries do not call themselves Mozilla.
        if (req.get_header_value("User-Agent").starts_with("Mozilla/")) {
          send(res, error_reply(403,
                                "User-Agent: browsers are refused (the API changes live "
                                "links; use curl or a client library)"));
          return httplib::Server::HandlerResponse::Handled;
        }
        bool allowed = false;
        {
          std::lock_guard lock(state->mutex);
          allowed = state->rate.allow(std::chrono::steady_clock::now().time_since_epoch());
        }
        if (allowed) return httplib::Server::HandlerResponse::Unhandled;
        ApiReply reply = error_reply(429, too_many);
        reply.headers.emplace_back("Retry-After", "1");
        send(res, reply);
        return httplib::Server::HandlerResponse::Handled;
      });

  // Every request is answered on the proxies' thread; this one waits.
  std::weak_ptr<State> alive = state_;
  const auto handler = [this, state, alive](const httplib::Request& req, httplib::Response& res) {
    ApiRequest request;
    request.method = req.method == "HEAD" ? "GET" : req.method;
    request.path = raw_path(req);
    for (const auto& [key, value] : req.params)
      request.query.emplace_back(key, value);
    request.content_type = req.get_header_value("Content-Type");
    request.body = req.body;
    auto promise = std::make_shared<std::promise<ApiReply>>();
    auto reply = promise->get_future();
    // Runs after this thread may have given up waiting: it answers only
    // while the server is alive.
    asio::post(io_,
               [&hub = hub_, info = options_.info, alive, promise, request = std::move(request)] {
                 if (alive.expired()) return;
                 promise->set_value(handle_api_request(hub, request, info));
               });
    // Waits in short steps so stop() (run on the proxies' thread, which
    // joins this one) never waits out the whole limit.
    const auto deadline = std::chrono::steady_clock::now() + kAnswerWait;
    while (reply.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) {
      bool stopping = false;
      {
        std::lock_guard lock(state->mutex);
        stopping = state->stopping;
      }
      if (stopping || std::chrono::steady_clock::now() > deadline) {
        send(res, error_reply(503, stopping ? "proxy: hil proxy is stopping"
                                            : "proxy: the proxies did not answer in time"));
        return;
      }
    }
    send(res, reply.get());
  };
  const std::string any = ".*";
  http.Get(any, handler);
  http.Post(any, handler);
  http.Put(any, handler);
  http.Patch(any, handler);
  http.Delete(any, handler);
  http.Options(any, handler);

  http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    if (res.status == 413) {
      const std::string length = req.get_header_value("Content-Length");
      const bool counted = !length.empty() && length.size() < 20 &&
                           length.find_first_not_of("0123456789") == std::string::npos;
      const std::string limit = std::to_string(kMaxApiBodyBytes);
      send(res,
           error_reply(413, counted ? "body: " + length + " bytes is over the limit of " + limit
                                    : "body: over the limit of " + limit + " bytes"));
    } else {
      send(res, error_reply(res.status, "request: HTTP " + std::to_string(res.status) +
                                            " (the request could not be read)"));
    }
  });

  if (options_.port == 0) {
    const int port = http.bind_to_any_port(options_.host);
    if (port <= 0) throw std::runtime_error("cannot listen on " + options_.host + " (any port)");
    state->port = static_cast<std::uint16_t>(port);
  } else {
    if (!http.bind_to_port(options_.host, options_.port))
      throw std::runtime_error("cannot listen on " + options_.host + ":" +
                               std::to_string(options_.port) + " (in use?)");
    state->port = options_.port;
  }
  state->running = true;
  state->thread = std::thread([state] {
    state->http.listen_after_bind();
    state->listen_returned = true;
  });
}

void ApiServer::stop() {
  State& state = *state_;
  if (!state.running) return;
  state.running = false;
  {
    std::lock_guard lock(state.mutex);
    state.stopping = true;
  }
  // httplib's stop() does nothing before its accept loop runs, and the loop
  // would then wait for a connection for ever: wait until it runs (or has
  // already ended) before stopping it.
  while (!state.http.is_running() && !state.listen_returned)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  state.http.stop();
  if (state.thread.joinable()) state.thread.join();
}

}  // namespace hil::control

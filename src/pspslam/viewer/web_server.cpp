#include "pspslam/viewer/web_server.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iterator>
#include <thread>
#include <utility>

#include "pspslam/core/error.h"
#include "pspslam/viewer/endpoint.h"

// Last: through <resolv.h> it defines a macro `_res`, which Eigen uses as a parameter name.
#include <httplib.h>

namespace pspslam {
namespace {

namespace fs = std::filesystem;

std::string content_type(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".png") return "image/png";
  return "application/octet-stream";
}

// Each event stream holds one of httplib's pool threads for as long as the page is open; more
// than this many would leave too few threads for the page's other requests.
constexpr int kMaxEventStreams = 4;

void answer(const HttpReply& reply, httplib::Response& response) {
  response.status = reply.status;
  // The page polls versioned URLs; a cached answer would freeze it.
  response.set_header("Cache-Control", "no-store");
  response.set_content(reply.body ? *reply.body : std::string(), reply.content_type.c_str());
}

WebServer::Query query_of(const httplib::Request& request) {
  return [&request](const std::string& name) {
    return request.has_param(name.c_str()) ? request.get_param_value(name.c_str()) : std::string();
  };
}

}  // namespace

// httplib has already percent-decoded the path, so "%2e%2e%2f" arrives as "../" and is refused
// like a literal one; a '%' left after decoding (double encoding) or a backslash is refused too.
// The canonical-prefix check stays as a second wall should a segment test ever miss a case.
std::optional<fs::path> asset_file(const fs::path& root, const std::string& request_path,
                                   const std::string& index_file) {
  if (request_path.empty() || request_path.front() != '/') return std::nullopt;
  std::string relative = request_path == "/" ? index_file : request_path.substr(1);
  // three.js lives under the npm folder; the page imports it as /vendor/three/...
  const std::string vendor = "vendor/three/";
  if (relative.rfind(vendor, 0) == 0)
    relative = "node_modules/three/" + relative.substr(vendor.size());
  if (relative.find_first_of("\\%") != std::string::npos ||
      relative.find('\0') != std::string::npos) {
    return std::nullopt;
  }
  for (const fs::path& part : fs::path(relative)) {
    if (part == ".." || part == "." || part.is_absolute() || part.has_root_name())
      return std::nullopt;
  }
  std::error_code failure;
  const fs::path canonical_root = fs::canonical(root, failure);
  if (failure) return std::nullopt;
  const fs::path file = fs::weakly_canonical(canonical_root / relative, failure);
  if (failure) return std::nullopt;
  const auto [root_end, unused] =
      std::mismatch(canonical_root.begin(), canonical_root.end(), file.begin(), file.end());
  if (root_end != canonical_root.end()) return std::nullopt;
  if (!fs::is_regular_file(file, failure)) return std::nullopt;
  return file;
}

struct WebServer::Impl {
  fs::path root;
  std::string index_file;
  httplib::Server server;
  std::thread thread;
  std::atomic<int> event_streams{0};
};

WebServer::WebServer(fs::path web_root, std::string index_file) : impl_(std::make_unique<Impl>()) {
  if (!fs::is_regular_file(web_root / index_file) ||
      !fs::is_regular_file(web_root / "node_modules/three/build/three.module.js")) {
    throw Error(web_root.string() +
                ": the viewer's page or three.js is missing (scripts/install-deps runs 'npm ci' "
                "in web/)");
  }
  impl_->root = std::move(web_root);
  impl_->index_file = std::move(index_file);
  // httplib's default also sets SO_REUSEPORT, with which a second run on the same port binds
  // silently and the two share (and split) the browser's requests. SO_REUSEADDR alone still
  // lets a port be reused right after a run ended (TIME_WAIT).
  impl_->server.set_socket_options([](socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  // Debian's httplib compresses every text or JSON answer for a client that accepts it, with
  // brotli at its slowest quality: every map snapshot and event then costs CPU time that is taken
  // from SLAM while a page is open, to save bytes that mostly cross loopback. Requests are answered
  // uncompressed; the Request is httplib's own non-const object, so dropping the header there is
  // sound.
  impl_->server.set_pre_routing_handler([](const httplib::Request& request, httplib::Response&) {
    const_cast<httplib::Request&>(request).headers.erase("Accept-Encoding");
    return httplib::Server::HandlerResponse::Unhandled;
  });
}

WebServer::~WebServer() { stop(); }

void WebServer::get(const std::string& route, Handler handler) {
  impl_->server.Get(route, [handler = std::move(handler)](const httplib::Request& request,
                                                          httplib::Response& response) {
    answer(handler(query_of(request)), response);
  });
}

void WebServer::post(const std::string& route, Handler handler) {
  impl_->server.Post(route, [handler = std::move(handler)](const httplib::Request& request,
                                                           httplib::Response& response) {
    answer(handler(query_of(request)), response);
  });
}

void WebServer::events(const std::string& route, EventWaiter waiter) {
  Impl* impl = impl_.get();
  impl_->server.Get(route, [impl, waiter = std::move(waiter)](const httplib::Request&,
                                                              httplib::Response& response) {
    if (impl->event_streams.fetch_add(1) >= kMaxEventStreams) {
      impl->event_streams.fetch_sub(1);
      answer({503, "text/plain", std::make_shared<const std::string>("too many event streams\n")},
             response);
      return;
    }
    response.set_header("Cache-Control", "no-store");
    auto last = std::make_shared<std::uint64_t>(0);
    response.set_chunked_content_provider(
        "text/event-stream",
        [waiter, last](size_t, httplib::DataSink& sink) {
          const std::optional<std::string> data = waiter(*last);
          if (!data) {
            sink.done();
            return true;
          }
          // An empty answer keeps the connection alive (a comment line) and lets httplib notice
          // a stopping server or a closed page between events; the data is one line of JSON.
          const std::string event = data->empty() ? ": idle\n\n" : "data: " + *data + "\n\n";
          return sink.write(event.data(), event.size());
        },
        [impl](bool) { impl->event_streams.fetch_sub(1); });
  });
}

std::string WebServer::listen(const std::string& endpoint_text) {
  const Endpoint endpoint = parse_endpoint(endpoint_text);
  const fs::path& root = impl_->root;
  const std::string& index_file = impl_->index_file;
  impl_->server.Get(
      R"(/.*)", [&root, &index_file](const httplib::Request& request, httplib::Response& response) {
        const std::optional<fs::path> file = asset_file(root, request.path, index_file);
        if (!file) {
          response.status = 404;
          response.set_content("not found\n", "text/plain");
          return;
        }
        std::ifstream stream(*file, std::ios::binary);
        response.set_content(std::string(std::istreambuf_iterator<char>(stream), {}),
                             content_type(*file).c_str());
      });
  httplib::Server& server = impl_->server;
  int port = endpoint.port;
  if (port == 0) {
    port = server.bind_to_any_port(endpoint.host.c_str());
  } else if (!server.bind_to_port(endpoint.host.c_str(), port)) {
    port = -1;
  }
  if (port <= 0) {
    throw Error("--viewer " + endpoint_text + ": cannot listen on " + endpoint.host + ":" +
                std::to_string(endpoint.port) +
                " (port in use, or not an address of this machine)");
  }
  if (!is_loopback(endpoint.host)) {
    spdlog::warn("the viewer listens on {}: anyone who can reach this machine can see the run",
                 endpoint.host);
  }
  impl_->thread = std::thread([&server] { server.listen_after_bind(); });
  // stop() before the thread is listening would be lost and the join would hang.
  for (int i = 0; i < 5000 && !server.is_running(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const bool v6 = endpoint.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + endpoint.host + "]" : endpoint.host) + ":" + std::to_string(port) +
         "/";
}

int WebServer::open_event_streams() const { return impl_->event_streams.load(); }

void WebServer::stop() {
  if (!impl_->thread.joinable()) return;
  impl_->server.stop();
  impl_->thread.join();
}

}  // namespace pspslam

#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace pspslam {

// One answer of the server. The body is shared so that a snapshot served to many clients is
// never copied per request.
struct HttpReply {
  int status = 200;
  std::string content_type = "application/json";
  std::shared_ptr<const std::string> body;
};

// The viewer's HTTP server (cpp-httplib, hidden here so its macros stay out of other headers):
// the page's own folder, JSON/binary routes and Server-Sent Event streams, served by httplib's
// thread pool while a listening thread of its own accepts connections. Only files under the
// asset folder are ever served, whatever the URL says (asset_file()).
class WebServer {
 public:
  // Reads a request's query parameter (empty when absent).
  using Query = std::function<std::string(const std::string& name)>;
  using Handler = std::function<HttpReply(const Query& query)>;
  // Called repeatedly on the connection's thread: blocks until the next event's data is ready
  // and returns it, or nothing to end the stream; an empty string is a keep-alive (return one
  // every second or so, so that a closed page or a stopping server is noticed). `last` is the
  // version the client has seen.
  using EventWaiter = std::function<std::optional<std::string>(std::uint64_t& last)>;

  // `web_root` holds index_file and the npm folder node_modules/three (served as /vendor/three);
  // throws pspslam::Error when either is missing.
  WebServer(std::filesystem::path web_root, std::string index_file = "index.html");
  ~WebServer();  // stops and joins the listening thread
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // Routes, before listen().
  void get(const std::string& route, Handler handler);
  void post(const std::string& route, Handler handler);
  void events(const std::string& route, EventWaiter waiter);

  // Binds `endpoint` ([HOST:]PORT text of --viewer; port 0 = a free one), starts serving on a
  // thread of its own and returns the address to open. Warns (spdlog) when the host is not a
  // loopback address. Throws pspslam::Error naming --viewer when it cannot listen.
  std::string listen(const std::string& endpoint);
  // Event streams open now (pages attached).
  int open_event_streams() const;

  // Stops accepting and waits for the open requests (event streams must end by themselves, see
  // EventWaiter). Idempotent; the destructor calls it.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The file that a request path names inside `root`, or nothing: `..`, `.`, a backslash, a '%'
// left after percent-decoding (double encoding) and anything whose canonical path leaves `root`
// are refused. "/" names `index_file`; "/vendor/three/..." names node_modules/three/....
std::optional<std::filesystem::path> asset_file(const std::filesystem::path& root,
                                                const std::string& request_path,
                                                const std::string& index_file = "index.html");

}  // namespace pspslam

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/viewer/endpoint.h"
#include "pspslam/viewer/live_viewer.h"
#include "pspslam/viewer/web_server.h"
#include "support/test_support.h"

// Last: through <resolv.h> it defines a macro `_res`, which Eigen uses as a parameter name.
#include <httplib.h>

namespace pspslam {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

// web/ with the page, a script and three.js; a secret next to it and a link leading out.
fs::path web_folder() {
  const fs::path dir = testing::make_temp_dir("viewer_web");
  write(dir / "web/index.html", "<html>index</html>");
  write(dir / "web/live.html", "<html>live</html>");
  write(dir / "web/sub/x.js", "let x;");
  write(dir / "web/node_modules/three/build/three.module.js", "export {};");
  write(dir / "secret.txt", "root:x:0:0");
  std::error_code ignored;
  fs::create_symlink(dir / "secret.txt", dir / "web/link", ignored);
  return dir / "web";
}

TEST(ViewerEndpoint, ParsesHostAndPort) {
  EXPECT_EQ(parse_endpoint("8080").host, "127.0.0.1");
  EXPECT_EQ(parse_endpoint("8080").port, 8080);
  EXPECT_EQ(parse_endpoint("0.0.0.0:0").host, "0.0.0.0");
  EXPECT_EQ(parse_endpoint("0.0.0.0:0").port, 0);
  EXPECT_EQ(parse_endpoint("[::1]:9000").host, "::1");
  EXPECT_EQ(parse_endpoint("[::1]:9000").port, 9000);
  for (const char* bad : {"70000", "host:", ":80", "abc", "127.0.0.1:-1", "123456"}) {
    try {
      parse_endpoint(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("[HOST:]PORT"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(is_loopback("127.0.0.1"));
  EXPECT_TRUE(is_loopback("::1"));
  EXPECT_TRUE(is_loopback("localhost"));
  EXPECT_FALSE(is_loopback("0.0.0.0"));
  EXPECT_FALSE(is_loopback("192.168.1.2"));
}

// The live page's "people" elements: what live.js reads, rounded, and a null pixel for a person
// not placed on the frame.
TEST(ViewerLivePeople, PersonJson) {
  TrackedPerson person;
  person.id = 7;
  person.position = {1.0, -0.5, 3.25};
  person.velocity = {0.5, 0.0, -0.25};
  person.extent_m = 1.234;
  person.visible_pixels = 900;
  const nlohmann::json placed = person_json({person, Eigen::Vector2d(320.04, 239.96)});
  EXPECT_EQ(placed["id"], 7);
  EXPECT_EQ(placed["p"], nlohmann::json({1.0, -0.5, 3.25}));
  EXPECT_EQ(placed["v"], nlohmann::json({0.5, 0.0, -0.25}));
  EXPECT_DOUBLE_EQ(placed["extent"].get<double>(), 1.23);
  EXPECT_TRUE(placed["seen"].get<bool>());
  EXPECT_EQ(placed["pixel"], nlohmann::json({320.0, 240.0}));
  person.visible_pixels = 0;  // predicted only
  const nlohmann::json coasting = person_json({person, std::nullopt});
  EXPECT_FALSE(coasting["seen"].get<bool>());
  EXPECT_TRUE(coasting["pixel"].is_null());
}

// The grid layer: counts and placement in the JSON, the picture upside down (an image's top row
// is the grid's highest) with unknown cells clear.
TEST(ViewerLiveGrid, JsonAndPicture) {
  OccupancyGrid grid;
  grid.resolution = 0.1;
  grid.origin = {-1.0, 2.0};
  grid.width = 3;
  grid.height = 2;
  grid.cells = {kGridOccupied, kGridFree, kGridUnknown, kGridFree, kGridFree, kGridUnknown};
  grid.T_world_grid.translation() = Eigen::Vector3d(0.0, 1.5, 0.0);
  const nlohmann::json json = grid_json(grid, 4);
  EXPECT_EQ(json["version"], 4);
  EXPECT_EQ(json["width"], 3);
  EXPECT_EQ(json["height"], 2);
  EXPECT_EQ(json["origin"], nlohmann::json({-1.0, 2.0}));
  EXPECT_EQ(json["cells"], nlohmann::json({{"unknown", 2}, {"free", 3}, {"occupied", 1}}));
  ASSERT_EQ(json["T_world_grid"].size(), 16u);
  EXPECT_DOUBLE_EQ(json["T_world_grid"][7].get<double>(), 1.5);  // row-major: y translation
  const cv::Mat picture = grid_picture(grid);
  ASSERT_EQ(picture.size(), cv::Size(3, 2));
  EXPECT_EQ(picture.at<cv::Vec4b>(1, 0)[3], 230);  // grid row 0 is the bottom image row
  EXPECT_GT(picture.at<cv::Vec4b>(1, 1)[3], 0);
  EXPECT_EQ(picture.at<cv::Vec4b>(1, 2)[3], 0);   // unknown: clear
  EXPECT_EQ(picture.at<cv::Vec4b>(0, 0)[3], 90);  // free
}

TEST(ViewerAssets, OnlyFilesInsideTheFolder) {
  const fs::path web = web_folder();
  const fs::path root = fs::canonical(web);
  EXPECT_EQ(asset_file(web, "/"), root / "index.html");
  EXPECT_EQ(asset_file(web, "/", "live.html"), root / "live.html");
  EXPECT_EQ(asset_file(web, "/sub/x.js"), root / "sub/x.js");
  EXPECT_EQ(asset_file(web, "/vendor/three/build/three.module.js"),
            root / "node_modules/three/build/three.module.js");
  // httplib hands the handler percent-decoded paths; a '%' left over is double encoding.
  for (const char* refused :
       {"/../secret.txt", "/sub/../../secret.txt", "/./index.html", "/%2e%2e/secret.txt", "/link",
        "/sub", "/missing.js", "index.html", "", "/sub\\x.js", "/vendor/three/../../../secret.txt",
        "//etc/passwd"}) {
    EXPECT_FALSE(asset_file(web, refused)) << refused;
  }
}

TEST(ViewerServer, MissingPageIsAnError) {
  const fs::path empty = testing::make_temp_dir("viewer_empty");
  try {
    WebServer server(empty);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("npm ci"), std::string::npos) << e.what();
  }
}

TEST(ViewerServer, RoutesEventsAndStop) {
  WebServer server(web_folder(), "live.html");
  server.get("/api/hello", [](const WebServer::Query& query) {
    return HttpReply{200, "application/json",
                     std::make_shared<const std::string>("{\"name\":\"" + query("name") + "\"}")};
  });
  server.post("/api/refuse", [](const WebServer::Query&) {
    return HttpReply{409, "text/plain", std::make_shared<const std::string>("no\n")};
  });
  // Three events, a keep-alive between them, then the end of the stream.
  server.events("/api/events", [](std::uint64_t& last) -> std::optional<std::string> {
    if (last >= 3) return std::nullopt;
    ++last;
    if (last == 2) return std::string();
    return "{\"n\":" + std::to_string(last) + "}";
  });
  const std::string url = server.listen("127.0.0.1:0");
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  const int port = std::stoi(url.substr(std::string("http://127.0.0.1:").size()));
  httplib::Client client("127.0.0.1", port);

  const auto hello = client.Get("/api/hello?name=pspslam");
  ASSERT_TRUE(hello);
  EXPECT_EQ(hello->status, 200);
  EXPECT_EQ(hello->body, "{\"name\":\"pspslam\"}");
  EXPECT_EQ(hello->get_header_value("Cache-Control"), "no-store");
  // Never compressed: httplib's brotli costs far more CPU than the bytes are worth on loopback.
  client.set_decompress(false);
  const auto plain = client.Get("/api/hello?name=x", {{"Accept-Encoding", "gzip, deflate, br"}});
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->get_header_value("Content-Encoding"), "");
  EXPECT_EQ(plain->body, "{\"name\":\"x\"}");
  const auto refused = client.Post("/api/refuse");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 409);
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->body, "<html>live</html>");
  EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
  const auto outside = client.Get("/../secret.txt");
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->status, 404);

  std::string stream;
  const auto events = client.Get("/api/events", [&](const char* data, size_t size) {
    stream.append(data, size);
    return true;
  });
  ASSERT_TRUE(events);
  EXPECT_EQ(events->get_header_value("Content-Type"), "text/event-stream");
  EXPECT_EQ(stream, "data: {\"n\":1}\n\n: idle\n\ndata: {\"n\":3}\n\n");

  server.stop();
  server.stop();  // idempotent
  EXPECT_FALSE(client.Get("/api/hello"));
}

// httplib's default socket options would let the second bind succeed (SO_REUSEPORT).
TEST(ViewerServer, PortInUseIsAnError) {
  WebServer first(web_folder());
  const std::string url = first.listen("127.0.0.1:0");
  const std::string port = url.substr(std::string("http://127.0.0.1:").size());
  WebServer second(web_folder());
  try {
    second.listen("127.0.0.1:" + port.substr(0, port.size() - 1));
    ADD_FAILURE() << "bound twice";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pspslam

#pragma once

#include <string>

namespace pspslam {

// Where the viewer listens (`--viewer [HOST:]PORT`).
struct Endpoint {
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port
};

// "[HOST:]PORT"; the last ':' splits, and "[::1]:8080" loses its brackets. Throws pspslam::Error
// naming the flag's text.
Endpoint parse_endpoint(const std::string& text);

// True for the addresses only this machine can reach (127.0.0.0/8, ::1, localhost).
bool is_loopback(const std::string& host);

}  // namespace pspslam

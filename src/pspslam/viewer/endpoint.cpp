#include "pspslam/viewer/endpoint.h"

#include "pspslam/core/error.h"

namespace pspslam {

Endpoint parse_endpoint(const std::string& text) {
  Endpoint endpoint;
  std::string port_text = text;
  if (const size_t colon = text.rfind(':'); colon != std::string::npos) {
    endpoint.host = text.substr(0, colon);
    if (endpoint.host.size() >= 2 && endpoint.host.front() == '[' && endpoint.host.back() == ']')
      endpoint.host = endpoint.host.substr(1, endpoint.host.size() - 2);
    port_text = text.substr(colon + 1);
  }
  const bool digits = !port_text.empty() && port_text.size() <= 5 &&
                      port_text.find_first_not_of("0123456789") == std::string::npos;
  if (endpoint.host.empty() || !digits || std::stoi(port_text) > 65535) {
    throw Error("--viewer " + text + ": expected [HOST:]PORT with PORT 0-65535 (0: any free port)");
  }
  endpoint.port = std::stoi(port_text);
  return endpoint;
}

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

}  // namespace pspslam

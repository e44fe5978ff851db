#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace texlume::apps {

/// One answer of a request handler. The body is shared, so files held in
/// memory are served without a copy.
struct HttpResponse {
  int status = 200;
  std::string content_type = "application/octet-stream";
  std::shared_ptr<const std::vector<unsigned char>> body;
};

/// Request path (no query string, percent-decoded) -> response.
using HttpHandler = std::function<HttpResponse(const std::string& path)>;

/// A small HTTP/1.1 server for local previews (cpp-httplib): GET and HEAD only.
/// Connections are answered concurrently by a pool of kMaxConnections threads,
/// so that a large file does not hold up the scripts a page loads beside it;
/// the handler must be safe to call from several threads.
class HttpServer {
 public:
  /// Binds to host:port (port 0: any free port). Throws std::runtime_error
  /// naming the address when it cannot.
  HttpServer(const std::string& host, int port);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;
  int port() const { return port_; }
  static constexpr int kMaxConnections = 8;
  /// Serves until `stop` turns true (checked every 200 ms); returns once every
  /// connection in progress is answered.
  void Serve(const HttpHandler& handler, const std::atomic<bool>& stop);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

/// The MIME type of a file name by its extension.
std::string ContentTypeOf(const std::string& name);

}  // namespace texlume::apps

#include "apps/http_server.h"

#include <arpa/inet.h>
#include <httplib.h>

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace texlume::apps {

struct HttpServer::Impl {
  httplib::Server server;
};

std::string ContentTypeOf(const std::string& name) {
  auto ends = [&](const char* ext) {
    const std::size_t n = std::strlen(ext);
    return name.size() >= n && name.compare(name.size() - n, n, ext) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js") || ends(".mjs")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".json")) return "application/json";
  if (ends(".png")) return "image/png";
  if (ends(".glb")) return "model/gltf-binary";
  return "application/octet-stream";
}

HttpServer::HttpServer(const std::string& host, int port) : impl_(std::make_unique<Impl>()) {
  const std::string address = host + ":" + std::to_string(port);
  if (port < 0 || port > 65535) throw std::runtime_error("port must be in [0, 65535]: " + address);
  in_addr parsed{};
  if (::inet_pton(AF_INET, host.c_str(), &parsed) != 1)
    throw std::runtime_error("not an IPv4 address: " + host);
  httplib::Server& server = impl_->server;
  // Requests are paths only; at most kMaxConnections answered at a time.
  server.set_payload_max_length(16384);
  server.new_task_queue = [] { return new httplib::ThreadPool(kMaxConnections); };
  port_ = port == 0 ? server.bind_to_any_port(host) : (server.bind_to_port(host, port) ? port : -1);
  if (port_ <= 0) throw std::runtime_error("cannot listen on " + address + ": " + strerror(errno));
}

HttpServer::~HttpServer() = default;

void HttpServer::Serve(const HttpHandler& handler, const std::atomic<bool>& stop) {
  httplib::Server& server = impl_->server;
  // GET (and HEAD, which cpp-httplib answers from the GET handler); bodies are
  // shared with the handler's caller and streamed without a copy.
  server.Get(".*", [&handler](const httplib::Request& request, httplib::Response& response) {
    const HttpResponse answer = handler(request.path);
    response.status = answer.status;
    if (!answer.body) {
      response.set_content("", answer.content_type);
      return;
    }
    const std::shared_ptr<const std::vector<unsigned char>> body = answer.body;
    response.set_content_provider(
        body->size(), answer.content_type,
        [body](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
          return sink.write(reinterpret_cast<const char*>(body->data()) + offset, length);
        });
  });
  std::thread listener([&server] { server.listen_after_bind(); });
  while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(200));
  server.stop();
  listener.join();
}

}  // namespace texlume::apps

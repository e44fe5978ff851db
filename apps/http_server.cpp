#include "apps/http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace texlume::apps {
namespace {

constexpr std::size_t kMaxRequestBytes = 16384;

bool SendAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::send(fd, p, size, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

std::string PercentDecode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

const char* Reason(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    default:
      return "Internal Server Error";
  }
}

void Answer(int fd, const HttpHandler& handler) {
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
  std::string request;
  char buffer[4096];
  while (request.find("\r\n\r\n") == std::string::npos && request.size() < kMaxRequestBytes) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    request.append(buffer, static_cast<std::size_t>(n));
  }
  std::istringstream line(request.substr(0, request.find("\r\n")));
  std::string method, target, version;
  line >> method >> target >> version;
  HttpResponse response;
  if (version.rfind("HTTP/1.", 0) != 0 || target.empty() || target[0] != '/') {
    response = {400, "text/plain", {}};
  } else if (method != "GET" && method != "HEAD") {
    response = {405, "text/plain", {}};
  } else {
    const std::string path = PercentDecode(target.substr(0, target.find_first_of("?#")));
    try {
      response = handler(path);
    } catch (const std::exception& e) {
      const std::string what = e.what();
      response = {500, "text/plain",
                  std::make_shared<const std::vector<unsigned char>>(what.begin(), what.end())};
    }
  }
  if (!response.body || (response.status != 200 && response.body->empty())) {
    const std::string text = response.status == 200
                                 ? std::string()
                                 : std::to_string(response.status) + " " + Reason(response.status);
    response.body = std::make_shared<const std::vector<unsigned char>>(text.begin(), text.end());
    if (response.status != 200) response.content_type = "text/plain";
  }
  std::ostringstream head;
  head << "HTTP/1.1 " << response.status << " " << Reason(response.status) << "\r\n"
       << "Content-Type: " << response.content_type << "\r\n"
       << "Content-Length: " << response.body->size() << "\r\n"
       << "Cache-Control: no-store\r\nConnection: close\r\n\r\n";
  const std::string h = head.str();
  if (!SendAll(fd, h.data(), h.size())) return;
  if (method != "HEAD") SendAll(fd, response.body->data(), response.body->size());
}

}  // namespace

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

HttpServer::HttpServer(const std::string& host, int port) {
  const std::string address = host + ":" + std::to_string(port);
  if (port < 0 || port > 65535) throw std::runtime_error("port must be in [0, 65535]: " + address);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1)
    throw std::runtime_error("not an IPv4 address: " + host);
  socket_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (socket_ < 0)
    throw std::runtime_error(std::string("cannot open a socket: ") + strerror(errno));
  const int yes = 1;
  ::setsockopt(socket_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (::bind(socket_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(socket_, 64) != 0) {
    const std::string why = strerror(errno);
    ::close(socket_);
    throw std::runtime_error("cannot listen on " + address + ": " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(socket_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

HttpServer::~HttpServer() {
  if (socket_ >= 0) ::close(socket_);
}

void HttpServer::Serve(const HttpHandler& handler, const std::atomic<bool>& stop) {
  struct Connection {
    std::thread thread;
    std::shared_ptr<std::atomic<bool>> answered;
  };
  std::mutex mutex;
  std::condition_variable answered_one;
  int active = 0;
  std::vector<Connection> connections;
  while (!stop.load()) {
    pollfd p{socket_, POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) continue;
    {
      std::unique_lock lock(mutex);
      answered_one.wait(lock, [&] { return active < kMaxConnections; });
      ++active;
    }
    const int fd = ::accept4(socket_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) {
      std::lock_guard lock(mutex);
      --active;
      continue;
    }
    // Join the threads that have answered, so the list stays short.
    std::erase_if(connections, [](Connection& c) {
      if (!c.answered->load()) return false;
      c.thread.join();
      return true;
    });
    auto answered = std::make_shared<std::atomic<bool>>(false);
    connections.push_back({std::thread([fd, answered, &handler, &mutex, &answered_one, &active] {
                             Answer(fd, handler);
                             ::shutdown(fd, SHUT_WR);
                             ::close(fd);
                             answered->store(true);
                             std::lock_guard lock(mutex);
                             --active;
                             answered_one.notify_all();
                           }),
                           answered});
  }
  for (Connection& c : connections) c.thread.join();
}

}  // namespace texlume::apps

#include "apps/view_command.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "apps/http_server.h"
#include "core/errors.h"
#include "core/partial_output.h"
#include "model/web_model.h"

namespace texlume::apps {
namespace fs = std::filesystem;
namespace {

std::atomic<bool> g_stop_serving{false};
extern "C" void StopServing(int /*signal*/) { g_stop_serving.store(true); }

/// Where the viewer's page and npm packages are: $TEXLUME_WEB_DIR, else the
/// source tree's web/ (the build records it).
fs::path WebDir() {
  if (const char* env = std::getenv("TEXLUME_WEB_DIR")) return env;
  return TEXLUME_SOURCE_WEB_DIR;
}

/// A file below `root` for a request path below a prefix; nullopt when the path
/// tries to leave `root` or names no regular file.
std::optional<fs::path> FileBelow(const fs::path& root, const std::string& rest) {
  if (rest.empty() || rest.find("..") != std::string::npos || rest.find('\\') != std::string::npos)
    return std::nullopt;
  const fs::path file = root / rest;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return std::nullopt;
  return file;
}

// The page loads web/viewer/viewer.js bundled with three.js by esbuild (`npm
// run build` in web/, run by ./scripts/install_deps.sh): refuse a missing or
// stale bundle.
void CheckViewerBundle(const fs::path& web) {
  const fs::path bundle = web / "dist/viewer.js";
  if (!fs::exists(web / "viewer/index.html") || !fs::exists(bundle))
    throw InputError(web.string(),
                     "has no viewer or no viewer bundle (dist/viewer.js); run "
                     "./scripts/install_deps.sh (it runs npm ci and npm run build in web/), or "
                     "set TEXLUME_WEB_DIR");
  for (const char* source : {"viewer/viewer.js", "package-lock.json"}) {
    std::error_code ec;
    const auto source_time = fs::last_write_time(web / source, ec);
    if (!ec && source_time > fs::last_write_time(bundle))
      throw InputError(bundle.string(), std::string("is older than ") + source +
                                            "; run `npm run build` in " + web.string() +
                                            " (or ./scripts/install_deps.sh)");
  }
}

HttpResponse FileResponse(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  HttpResponse r;
  r.content_type = ContentTypeOf(f.filename().string());
  r.body = std::make_shared<const std::vector<unsigned char>>(std::istreambuf_iterator<char>(in),
                                                              std::istreambuf_iterator<char>());
  return r;
}

using ModelFiles = std::map<std::string, std::shared_ptr<const std::vector<unsigned char>>>;

HttpResponse Answer(const fs::path& web, const ModelFiles& model_files, const std::string& path) {
  if (path == "/" || path == "/index.html") return FileResponse(web / "viewer/index.html");
  if (path.rfind("/viewer/", 0) == 0)
    if (const auto f = FileBelow(web / "viewer", path.substr(8))) return FileResponse(*f);
  if (path.rfind("/dist/", 0) == 0)
    if (const auto f = FileBelow(web / "dist", path.substr(6))) return FileResponse(*f);
  if (path.rfind("/model/", 0) == 0) {
    const auto it = model_files.find(path.substr(7));
    if (it != model_files.end()) return {200, ContentTypeOf(it->first), it->second};
  }
  return {404, "text/plain", {}};
}

}  // namespace

void ServeViewer(const ViewOptions& options, std::ostream& out, std::ostream& err) {
  const fs::path web = WebDir();
  CheckViewerBundle(web);
  const auto t0 = std::chrono::steady_clock::now();
  model::WebModel model = model::BuildWebModel(options.model_dir);
  const double prepare_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Served without a copy per request.
  ModelFiles model_files;
  for (auto& [name, bytes] : model.files)
    model_files[name] = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  HttpServer server(options.host, options.port);
  out << "texlume view: " << model.scene["faces"].get<std::size_t>() << " triangles, "
      << model.scene["atlases"].size() << " atlas(es), prepared in " << prepare_s << " s\n"
      << "Serving " << options.model_dir.string() << " at http://" << options.host << ":"
      << server.port() << "/ (Ctrl-C stops)" << std::endl;
  g_stop_serving.store(false);
  // Ctrl-C stops serving (the interrupt watcher calls StopServing; without one, a handler).
  if (!SetInterruptHandler(StopServing)) {
    std::signal(SIGINT, StopServing);
    std::signal(SIGTERM, StopServing);
  }
  server.Serve([&](const std::string& path) { return Answer(web, model_files, path); },
               g_stop_serving);
  SetInterruptHandler(nullptr);
  err << "texlume view: stopped\n";
}

}  // namespace texlume::apps

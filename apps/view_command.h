#pragma once

#include <filesystem>
#include <ostream>
#include <string>

namespace texlume::apps {

/// `texlume view`: the settings of the browser preview.
struct ViewOptions {
  std::filesystem::path model_dir;  ///< a model folder written by texlume synth
  int port = 8080;                  ///< [0, 65535]; 0: any free port
  std::string host = "127.0.0.1";
};

/// Serves the viewer page, its bundle and the model's web files on host:port
/// until SIGINT or SIGTERM (docs/viewer.md). Throws InputError when the viewer
/// bundle is missing or older than its sources, or the folder is not a model.
void ServeViewer(const ViewOptions& options, std::ostream& out, std::ostream& err);

}  // namespace texlume::apps

// Makes a scene's object photos large for bench/photo_cache_bench.sh: every photo of
// OBJECT_DIR resized by FACTOR (bicubic) and written as a JPEG of quality 90, the
// COLMAP model's cameras scaled to match, the lights renamed to the JPEGs, and the
// mesh copied, into OUT_OBJECT_DIR. The photos carry no more detail than before; what
// grows is what a job must decode and hold, which is what the bench measures.
// Usage: upscale_photos OBJECT_DIR OUT_OBJECT_DIR FACTOR
#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/image_io.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace fs = std::filesystem;
using namespace texlume;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s OBJECT_DIR OUT_OBJECT_DIR FACTOR\n", argv[0]);
    return 2;
  }
  try {
    const fs::path in = argv[1], out = argv[2];
    const double factor = std::stod(argv[3]);
    if (!(factor >= 1.0 && factor <= 16.0)) throw std::runtime_error("FACTOR must be in [1, 16]");
    sfm::Reconstruction model = sfm::ReadModel(in / "sparse").reconstruction;
    const sfm::ObjectLights lights = sfm::ReadObjectLightsFile(in / "lights.json");
    sfm::ObjectLights renamed;
    for (auto& [id, camera] : model.cameras) camera = camera.Scaled(factor);
    fs::create_directories(out / "images");
    std::size_t done = 0;
    for (auto& [id, image] : model.images) {
      const sfm::Camera& camera = model.cameras.at(image.camera_id);
      const cv::Mat photo = ReadPhotoRgb(in / "images" / image.name);
      cv::Mat large;
      cv::resize(photo, large,
                 cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)), 0, 0,
                 cv::INTER_CUBIC);
      const std::string jpeg = fs::path(image.name).replace_extension(".jpg").string();
      if (!cv::imwrite((out / "images" / jpeg).string(), ToBgr8(large),
                       {cv::IMWRITE_JPEG_QUALITY, 90}))
        throw std::runtime_error("cannot write " + (out / "images" / jpeg).string());
      if (lights.contains(image.name)) renamed[jpeg] = lights.at(image.name);
      image.name = jpeg;
      if (++done % 16 == 0) std::fprintf(stderr, "upscale_photos: %zu photos\n", done);
    }
    sfm::WriteModel(model, out / "sparse", sfm::ModelFormat::kBinary);
    sfm::WriteObjectLightsFile(renamed, out / "lights.json");
    fs::copy_file(in / "mesh.ply", out / "mesh.ply", fs::copy_options::overwrite_existing);
    const sfm::Camera& first = model.cameras.begin()->second;
    std::printf("upscale_photos: %zu photos of %llux%llu into %s\n", done,
                static_cast<unsigned long long>(first.width),
                static_cast<unsigned long long>(first.height), out.string().c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "upscale_photos: %s\n", e.what());
    return 1;
  }
}

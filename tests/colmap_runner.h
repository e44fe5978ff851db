#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/test_util.h"

namespace texlume::testing {

/// Runs COLMAP's own structure from motion on the CPU (feature_extractor with
/// one PINHOLE camera, a matcher, mapper) over a folder of photos, in `work`.
/// `sequential_overlap` > 0 matches each photo with the next that many by name
/// (sequential_matcher: photos named in the order they were taken, as on a
/// ring); 0 matches every pair (exhaustive_matcher). With `pinhole_params` ("fx,fy,cx,cy") the
/// camera is taken as calibrated (its intrinsics fixed), as for a camera whose calibration is
/// known; else COLMAP estimates them. Returns the first model's folder (work/sparse/0), or an empty
/// path after a test failure naming the step that failed, with its log.
inline std::filesystem::path RunColmapSfm(const std::filesystem::path& images,
                                          const std::filesystem::path& work,
                                          const std::string& pinhole_params = "",
                                          int sequential_overlap = 0) {
  const std::string calibrated =
      pinhole_params.empty() ? std::string() : " --ImageReader.camera_params " + pinhole_params;
  const std::string fixed_intrinsics = pinhole_params.empty()
                                           ? std::string()
                                           : " --Mapper.ba_refine_focal_length 0"
                                             " --Mapper.ba_refine_principal_point 0";
  const std::string db = (work / "db.db").string();
  std::filesystem::create_directories(work / "sparse");
  const std::string colmap = "QT_QPA_PLATFORM=offscreen colmap ";
  const std::string steps[] = {
      colmap + "feature_extractor --database_path " + db + " --image_path " + images.string() +
          " --SiftExtraction.use_gpu 0 --ImageReader.single_camera 1"
          " --ImageReader.camera_model PINHOLE" +
          calibrated,
      colmap +
          (sequential_overlap > 0 ? "sequential_matcher --SequentialMatching.overlap " +
                                        std::to_string(sequential_overlap)
                                  : std::string("exhaustive_matcher")) +
          " --database_path " + db + " --SiftMatching.use_gpu 0",
      colmap + "mapper --database_path " + db + " --image_path " + images.string() +
          " --output_path " + (work / "sparse").string() + fixed_intrinsics};
  for (const std::string& step : steps) {
    std::string log;
    if (RunCommand(step, &log) != 0) {
      ADD_FAILURE() << step << " failed:\n" << log;
      return {};
    }
  }
  return work / "sparse/0";
}

}  // namespace texlume::testing

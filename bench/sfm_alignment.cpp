// Compares a COLMAP reconstruction with a ground-truth model: registered share and
// the similarity alignment of camera centres. Used by bench/colmap_sfm_check.sh and
// bench/fidelity_bench.sh, which also writes the estimate moved into the ground
// truth's frame (OUT_MODEL, binary): COLMAP's cameras in the frame of the scene's mesh.
// Usage: sfm_alignment GROUND_TRUTH_MODEL ESTIMATED_MODEL [OUT_MODEL]
#include <cstdio>
#include <exception>

#include "sfm/alignment.h"
#include "sfm/colmap_io.h"

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: %s GROUND_TRUTH_MODEL ESTIMATED_MODEL [OUT_MODEL]\n", argv[0]);
    return 2;
  }
  try {
    using namespace texlume::sfm;
    const Reconstruction truth = ReadModel(argv[1]).reconstruction;
    const Reconstruction estimate = ReadModel(argv[2]).reconstruction;
    const SimilarityAlignment a = AlignByCameraCenters(truth, estimate);
    double extent = 0;
    for (const auto& [id, image] : truth.images)
      extent = std::max(extent, image.ProjectionCenter().norm());
    std::printf(
        "registered %zu/%zu, centre RMS %.3f %% of the camera distance, max rotation %.3f deg\n",
        estimate.images.size(), truth.images.size(), 100.0 * a.rms_center_error / extent,
        a.max_rotation_error_deg);
    if (argc == 4) WriteModel(TransformedIntoReference(estimate, a), argv[3], ModelFormat::kBinary);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

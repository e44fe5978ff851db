#pragma once

#include <cstddef>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "atlas/atlas.h"
#include "quilt/dense_surface.h"
#include "quilt/surface_quilting.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/material_sample.h"
#include "synth/triangle_engine.h"

// Paper 003's image term on the graph-cut engine's work patches (issue 32,
// beyond paper 004; docs/quilting.md, "Following the photos"): the sample,
// relit under a photo's lights and seen through the photo's resolution and
// blur, against the photo over the samples the patch is to synthesise at every
// placement of the rotated copy (eq. 3, RMS per photo, summed over the photos
// that see the seed's face fully).

namespace texlume::quilt {

/// The photos and their calibration against the sample: photo gains, white
/// balance, light response and blur (synth::TriangleEngine::Prepare). Every
/// reference must outlive the image term.
struct PhotoEvidence {
  const sfm::Reconstruction& reconstruction;
  const sfm::VisibilityResult& visibility;  ///< of the surface's mesh
  const std::vector<synth::MeshPhoto>& photos;
  const synth::TriangleSynthesis& photometry;
};

struct ImageTermOptions {
  bool all_views = true;     ///< every photo that sees the seed's face fully, not the best only
  int max_views = 4;         ///< most photos per patch
  int min_photo_pixels = 6;  ///< fewest photo pixels over the samples to synthesise, per photo
};

/// The image term of a work patch. Inside the patch the lighting is the seed
/// face's (paper 003 takes one lighting per triangle too; the face holding
/// most of the samples to synthesise did no better: docs/quilting.md).
/// Each sample the patch is to synthesise is compared with the photo where it projects, on
/// faces the photo sees fully; samples already synthesised are not (the cut
/// mostly keeps them).
class PhotoImageTerm : public PatchImageTerm {
 public:
  PhotoImageTerm(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                 const synth::MaterialSample& sample, const PhotoEvidence& photos,
                 const ImageTermOptions& options);

  Score Placements(int seed, const std::vector<WorkImageSample>& samples, cv::Size work_size,
                   int rotation, const RotatedSample& rotated) override;

 private:
  struct View {
    std::size_t photo = 0;
    double px_per_texel = 1.0;  ///< the photo's density over the seed's face
  };
  // The photos that see a face fully, best first.
  std::vector<View> ViewsOf(int face) const;
  // The photo at every work sample whose face it sees fully (sample domain,
  // white balance taken out); returns the pixels set in `mask`.
  int PhotoPlanes(const View& view, const std::vector<WorkImageSample>& samples, cv::Size work_size,
                  std::vector<cv::Mat>& planes, cv::Mat& mask) const;
  // The seed face's lighting in the photo (its atlas frame is the work
  // frame), in the sample's own frame once the copy turns it
  // by `copy_rad` within the work frame.
  synth::FaceLighting LightingOf(int face, const View& view, double copy_rad) const;
  // The copy relit under the view's lighting of a face, blurred as the photo sees it.
  const std::vector<cv::Mat>& RelitCopy(int face, const View& view, int rotation,
                                        const RotatedSample& rotated);
  bool SeesFully(std::size_t photo, int face) const;

  const DenseSurface& surface_;
  const atlas::AtlasLayout& layout_;
  const synth::MaterialSample& sample_;
  const PhotoEvidence photos_;  ///< references only
  const ImageTermOptions options_;
  std::map<sfm::ImageId, std::size_t> photo_index_;
  struct Relit {
    int rotation = -1;
    std::vector<cv::Mat> planes;
    cv::Mat energy;
  };
  /// Per photo, the copy last relit for relit_face_'s lighting (a retry of the
  /// same seed reuses it; another face clears them all).
  std::map<std::size_t, Relit> relit_;
  int relit_face_ = -1;
};

}  // namespace texlume::quilt

#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mesh/triangle_frame.h"
#include "ptm/horizon.h"
#include "ptm/light_response.h"
#include "ptm/ptm.h"
#include "sfm/lights.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

/// The domain in which a sample's relit values are compared with the photos
/// (eq. 3 of paper 003): the photos are rectified into it.
enum class PhotoDomain {
  kDisplay,  ///< sRGB-encoded display values in [0, 1] (PTMs hold them, as RTI tools fit them)
  kLinear,   ///< linear RGB (measured BTFs, and light mixtures)
};

/// What lights one face in one photo, in the face's frame: the direction
/// towards the camera and every light of the photo (direction towards the
/// light, unit; intensity). Lights below the face's horizon are kept: each
/// sample decides how they act. `response`: how the object answers lights
/// beyond the sample's own model, as the photos showed it (elevation factors
/// and ambient light, ptm::LightResponse; the identity until the engine has
/// estimated it). Every sample applies it: PTM and colour samples as
/// RelightMixture does, a BTF as render::ShadeBtf.
struct FaceLighting {
  Eigen::Vector3d view_in_frame = Eigen::Vector3d::UnitZ();
  std::vector<std::pair<Eigen::Vector3d, double>> lights;
  ptm::LightResponse response;
};

/// The lighting of a point in a photo, in a frame there (a face's, or a chart's
/// laid on the face): the direction towards the camera centre and every light
/// of the photo, with the response.
FaceLighting LightingInFrame(const mesh::TriangleFrame& frame,
                             const Eigen::Vector3d& camera_centre_in_world,
                             const std::vector<sfm::ObjectLight>& lights,
                             const ptm::LightResponse& response);

/// Relights windows of one reduced sample under one face lighting into planes the
/// caller holds, with Relight's values at every cell: for a search that relights the
/// cells its placements ask for, one window after another (synth/placement_search.h).
class WindowRelighter {
 public:
  virtual ~WindowRelighter() = default;
  /// Writes Relight(the reduced sample's window `cells`) into `out` (R, G, B planes
  /// of at least the reduced size) at `cells`.
  virtual void Relight(cv::Rect cells, std::array<cv::Mat, 3>& out) = 0;
};

/// A material sample as the synthesis engines see it (DESIGN.md, "Engines and
/// samples"). An engine never looks inside a sample: it compares feature
/// planes, turns them with the face frames, relights the sample for the image
/// constraint and asks whether values may be blended. Reductions are cached on
/// first use (Reduced, safe on several threads).
class MaterialSample {
 public:
  virtual ~MaterialSample() = default;

  /// "PTM", "BTF", "colour": for messages and manifests.
  virtual std::string Name() const = 0;
  /// Size in texels.
  virtual int Width() const = 0;
  virtual int Height() const = 0;

  /// Feature planes (CV_32FC1, full size) in which Euclidean distance is the
  /// right distance between texels (PTM: the orthonormal coefficients, paper
  /// 003 §2.3; BTF: the geometry maps, paper 004 §III).
  virtual const std::vector<cv::Mat>& FeaturePlanes() const = 0;
  int NumFeatures() const { return static_cast<int>(FeaturePlanes().size()); }

  /// The features a placed patch shows at a point of its face's frame (world
  /// units), with whatever the photo-consistency pass changed in them;
  /// false outside the patch rectangle. `out` holds NumFeatures() values.
  /// By default FeaturesAt the point's sample position (a pass that changes no
  /// feature).
  virtual bool PatchFeatures(const TrianglePatch& patch, double texel_size,
                             const Eigen::Vector2d& p_in_frame, float* out) const;
  /// The features at a continuous sample position (texels, x right, y down,
  /// centres at +0.5), bilinear, clamped to the sample.
  virtual void FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const = 0;
  /// Features of a neighbour's frame carried into this one across a shared
  /// edge (in place): what a rotation of the frame does to them.
  virtual void TurnFeatures(const Unfolding& unfolding, float* features) const = 0;

  /// Whether values of two patches may be mixed where they overlap (a PTM's
  /// coefficients may; a BTF's mesostructure must be cut, never blended).
  virtual bool Blendable() const = 0;
  /// Whether the view direction changes what the sample shows.
  virtual bool ViewDependent() const = 0;
  /// The domain of Relight's values (and of the photos compared with them).
  virtual PhotoDomain Domain() const = 0;

  /// What Relight reads, reduced to a photo density level (r = 2^(-level/4)
  /// photo pixels per texel; ReduceToDensityLevel), cached; safe on several threads.
  const ReducedPlanes& Reduced(int level) const;
  /// How many planes Reduced() reduces (each of the sample's size at level 0).
  int NumRelightPlanes() const { return static_cast<int>(RelightPlanes().size()); }
  /// The reduced sample relit under a face's lighting times a gain: 3 planes
  /// (R, G, B) of the reduced size, in Domain().
  virtual std::vector<cv::Mat> Relight(const ReducedPlanes& reduced, const FaceLighting& lighting,
                                       double gain) const = 0;
  /// Relight's values window by window, set up once for `reduced` (which must outlive
  /// it) under `lighting` and `gain`. By default each window is relit by Relight.
  virtual std::unique_ptr<WindowRelighter> RelighterOf(const ReducedPlanes& reduced,
                                                       const FaceLighting& lighting,
                                                       double gain) const;
  /// What `cells` texels of the sample sum to on average under a face's
  /// lighting, over R, G and B, in the linear domain (the photo gains compare
  /// it with the photo's sum over as many cells).
  virtual double RelitLinearSum(const FaceLighting& lighting, int cells) const = 0;

 protected:
  /// The planes Reduced() reduces.
  virtual const std::vector<cv::Mat>& RelightPlanes() const = 0;

 private:
  // A level's planes, reduced once by the first thread that asks for them; the
  // others wait for that level only.
  struct ReducedLevel {
    std::once_flag once;
    ReducedPlanes planes;
  };
  mutable std::mutex reduced_mutex_;  // guards the map, not the levels' reductions
  mutable std::map<int, ReducedLevel> reduced_;
};

class BilinearTaps;

/// A PTM sample (paper 003): features are the orthonormal coefficients (6 LRGB,
/// 18 RGB), turned by the frame rotation's 6 x 6 map; values (coefficients and
/// LRGB colour) may be blended; relit in the display domain (RelightMixture).
/// With its self-shadowing (`texlume fit --horizon`), each light's linear value is
/// multiplied by the relief's light factor (ptm::SelfShadowing), as the renderer
/// shades a model with horizon maps: the sample is relit with the shadows the
/// photos show. The face frame is the sample's texel frame (patches are not turned
/// in the sample), so a face's lights read the sample's horizon directly.
class PtmSample : public MaterialSample {
 public:
  /// `shadowing`: the sample's own (of its size), or null for none. Neither is copied:
  /// both must outlive the sample.
  explicit PtmSample(const ptm::Ptm& ptm, const ptm::SelfShadowing* shadowing = nullptr);

  std::string Name() const override { return "PTM"; }
  int Width() const override { return ptm_.width; }
  int Height() const override { return ptm_.height; }
  const std::vector<cv::Mat>& FeaturePlanes() const override { return coefficients_; }
  bool PatchFeatures(const TrianglePatch& patch, double texel_size,
                     const Eigen::Vector2d& p_in_frame, float* out) const override;
  void FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const override;
  void TurnFeatures(const Unfolding& unfolding, float* features) const override;
  bool Blendable() const override { return true; }
  bool ViewDependent() const override { return false; }
  PhotoDomain Domain() const override { return PhotoDomain::kDisplay; }
  std::vector<cv::Mat> Relight(const ReducedPlanes& reduced, const FaceLighting& lighting,
                               double gain) const override;
  /// Without relief shadows, the rows of each window relit in place (PtmRowRelighter).
  std::unique_ptr<WindowRelighter> RelighterOf(const ReducedPlanes& reduced,
                                               const FaceLighting& lighting,
                                               double gain) const override;
  double RelitLinearSum(const FaceLighting& lighting, int cells) const override;

  const ptm::Ptm& ptm() const { return ptm_; }
  ptm::PtmFormat format() const { return ptm_.format; }
  /// Coefficient planes (6 LRGB, 18 RGB); LRGB colour planes follow in Values().
  int CoefficientPlanes() const { return static_cast<int>(coefficients_.size()); }
  /// Everything a texel holds: orthonormal coefficients, then LRGB colour.
  const std::vector<cv::Mat>& Values() const { return values_; }
  /// Whether the sample casts the relief's shadows.
  bool CastsShadows() const { return shadowing_ != nullptr; }

  /// A face lighting's lights as the sample's texels answer them
  /// (ptm::EffectiveLights) and, when the sample casts shadows, where each falls
  /// among the horizon's sectors (nothing for the ambient light: it casts none).
  struct TexelLights {
    std::vector<ptm::EffectiveLight> lights;
    std::vector<std::optional<ptm::LightAmongSectors>> among_sectors;
  };
  TexelLights LightsOf(const FaceLighting& lighting) const;
  /// `lights` with each weight times the relief's light factor at the reduced
  /// sample's point `at` (bilinear taps of `reduced`'s size): the horizon's mean and
  /// spread over the point's cell (SelfShadowing::CellLightFactor). Unchanged when
  /// the sample casts no shadows.
  void ShadowLights(const TexelLights& lights, const ReducedPlanes& reduced, const BilinearTaps& at,
                    std::vector<ptm::EffectiveLight>& out) const;

 protected:
  /// Raw coefficients a0..a5 per polynomial, then LRGB colour: evaluation is
  /// linear in them, so reducing them equals reducing the relit image (up to
  /// the clamp). With self-shadowing, then per sector the horizon elevation and its
  /// square (radians): reduced, their means over a cell give the horizon's mean and
  /// spread there.
  const std::vector<cv::Mat>& RelightPlanes() const override { return raw_; }

 private:
  /// The index in RelightPlanes() of the first horizon plane.
  int HorizonPlanesBegin() const { return ptm_.NumPolynomials() * 6 + (lrgb() ? 3 : 0); }
  bool lrgb() const { return ptm_.format == ptm::PtmFormat::kLrgb; }

  const ptm::Ptm& ptm_;
  const ptm::SelfShadowing* shadowing_ = nullptr;
  std::vector<cv::Mat> values_, coefficients_, raw_;
  int coarse_level_ = 0;  ///< the level RelitLinearSum averages at (about 16 texels a side)
  /// With self-shadowing, what RelitLinearSum relights instead: the texels of a
  /// grid over the sample (kShadowedSumGrid a side), each with its own horizon, since
  /// a cell's shadow is not that of its mean horizon.
  ReducedPlanes shadowed_sum_texels_;
};

/// Bilinear value of a CV_32FC1 plane at (x, y) (pixel centres at integers),
/// clamped to the plane.
double BilinearClamped(const cv::Mat& plane, double x, double y);

/// BilinearClamped's taps and weights at one point of planes of one size, so that
/// several planes are read there with one computation of them (the same values).
class BilinearTaps {
 public:
  BilinearTaps(cv::Size planes, double x, double y);
  /// BilinearClamped(plane, x, y) for a plane of the size given.
  double Of(const cv::Mat& plane) const {
    const float* r0 = plane.ptr<float>(y0_);
    const float* r1 = plane.ptr<float>(y1_);
    return Blend(r0[x0_], r0[x1_], r1[x0_], r1[x1_]);
  }
  /// Of() of each channel of a CV_32FC(N) plane of the size given (the values of
  /// Of() on each channel split out; one read of the row pair).
  template <std::size_t N>
  void OfChannels(const cv::Mat& interleaved, std::array<double, N>& out) const {
    CV_DbgAssert(interleaved.type() == CV_32FC(static_cast<int>(N)));
    VisitChannels(interleaved, [&](int m, double v) { out[static_cast<std::size_t>(m)] = v; });
  }
  /// out[m] += scale x Of() of channel m, for every channel m of a CV_32FC(n) plane
  /// of the size given, each rounded to float as it is added.
  void AddScaledChannels(const cv::Mat& interleaved, double scale, float* out) const {
    VisitChannels(interleaved, [&](int m, double v) { out[m] += static_cast<float>(scale * v); });
  }

 private:
  template <typename Visit>
  void VisitChannels(const cv::Mat& interleaved, Visit visit) const {
    CV_DbgAssert(interleaved.depth() == CV_32F);
    const int n = interleaved.channels();
    const float* r0 = interleaved.ptr<float>(y0_);
    const float* r1 = interleaved.ptr<float>(y1_);
    for (int m = 0; m < n; ++m)
      visit(m, Blend(r0[x0_ * n + m], r0[x1_ * n + m], r1[x0_ * n + m], r1[x1_ * n + m]));
  }
  double Blend(float v00, float v10, float v01, float v11) const {
    return (1 - fy_) * ((1 - fx_) * v00 + fx_ * v10) + fy_ * ((1 - fx_) * v01 + fx_ * v11);
  }

  int x0_ = 0, x1_ = 0, y0_ = 0, y1_ = 0;
  double fx_ = 0.0, fy_ = 0.0;
};

/// The values of a PTM patch at a point of its face's frame (world units),
/// Catmull-Rom within the patch rectangle (its taps read the sample around it), with its
/// photo-consistency correction (additive change, per-channel factors) and detail transfer when it
/// has them (TrianglePatch); `detail_bands` by level as MeshSynthesis holds them. False outside the
/// rectangle. Writes values.size() planes.
bool SamplePtmPatch(const std::vector<cv::Mat>& values, ptm::PtmFormat format,
                    const std::map<int, cv::Mat>& detail_bands, const TrianglePatch& patch,
                    double texel_size, const Eigen::Vector2d& p_in_frame, float* out);

}  // namespace texlume::synth

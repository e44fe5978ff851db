#include "quilt/surface_quilting.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <string>
#include <unordered_map>

#include "core/check.h"
#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "quilt/work_patch.h"
#include "synth/min_cut.h"
#include "synth/triangle_parts.h"

namespace texlume::quilt {

void QuiltOptions::Check() const {
  if (min_work_patch_levels < 1 || work_patch_levels < min_work_patch_levels)
    throw OptionError("--work-patch must be at least the smallest work patch (" +
                      std::to_string(min_work_patch_levels) + " levels)");
  if (!(shrink > 0.0 && shrink < 1.0)) throw OptionError("the work patch shrink must be in (0, 1)");
  if (!(max_area_distortion >= 1.0)) throw OptionError("T_d must be at least 1");
  if (!(seam_threshold > 0.0)) throw OptionError("--seam-threshold must be positive");
  if (image_top_k < 1) throw OptionError("--top-k must be at least 1");
  if (random_orientation && !field_in_world.empty())
    throw OptionError("give a field or a random orientation, not both");
}

namespace {

constexpr double kForced = 1e30;  ///< a t-link that a cut never takes

float Bilinear(const cv::Mat& plane, double x, double y) {
  x = std::clamp(x - 0.5, 0.0, plane.cols - 1.0);
  y = std::clamp(y - 0.5, 0.0, plane.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), plane.cols - 2);
  const int y0 = std::min(static_cast<int>(y), plane.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = plane.ptr<float>(y0);
  const float* r1 = plane.ptr<float>(y0 + 1);
  return static_cast<float>((1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
                            fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]));
}

class SurfaceQuilter {
 public:
  SurfaceQuilter(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                 const synth::MaterialSample& sample, const QuiltOptions& options,
                 const GivenSamples* given, PatchImageTerm* image_term)
      : surface_(surface),
        layout_(layout),
        sample_(sample),
        options_(options),
        rotated_(sample),
        work_patches_(surface, layout, rotated_.side(), options.conformal_work_images),
        features_(sample.NumFeatures()),
        image_term_(image_term),
        rng_(options.seed) {
    if (2 * options.min_work_patch_levels + 1 > rotated_.side())
      throw InputError("the " + sample.Name() + " sample",
                       "is smaller than the smallest work patch (" +
                           std::to_string(2 * options.min_work_patch_levels + 1) +
                           " texels a side once turned)");
    MakeFieldAngles();
    result_.lookups.resize(surface.size());
    result_.patch_of.assign(surface.size(), -1);
    values_.assign(surface.size() * static_cast<std::size_t>(features_), 0.0f);
    synthesised_neighbours_.assign(surface.size(), 0);
    given_.assign(surface.size(), false);
    if (given) TakeGiven(*given);
    result_.stats.random_pair_cost = RandomPairCost();
  }

  QuiltResult Run(const ProgressCallback& progress) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t s = 0; s < surface_.size(); ++s)
      if (!given_[s]) queue_.emplace(synthesised_neighbours_[s], -static_cast<int>(s));
    std::size_t done = 0, reported = 0;
    const std::size_t total = surface_.size() - result_.stats.given;
    while (done < total) {
      const int v = MostConstrained();
      done += PlacePatchAt(v);
      if (progress && (done * 100 / total > reported * 100 / total || done == total)) {
        progress("quilting", done, total);
        reported = done;
      }
    }
    result_.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return std::move(result_);
  }

 private:
  // The given samples' features, and their counts as synthesised neighbours.
  void TakeGiven(const GivenSamples& given) {
    const std::size_t nf = static_cast<std::size_t>(features_);
    if (given.given.size() != surface_.size() || given.features.size() != surface_.size() * nf)
      throw std::invalid_argument("QuiltSurface: given samples of another surface");
    for (std::size_t s = 0; s < surface_.size(); ++s) {
      if (!given.given[s]) continue;
      given_[s] = true;
      ++result_.stats.given;
      std::copy_n(given.features.data() + s * nf, nf, ValuesOf(static_cast<int>(s)));
      for (const int nb : surface_.Neighbours(static_cast<int>(s)))
        ++synthesised_neighbours_[static_cast<std::size_t>(nb)];
    }
  }

  // Per face, the field's angle in its atlas frame (y up).
  void MakeFieldAngles() {
    for (std::size_t f = 0; f < layout_.faces.size(); ++f) {
      const AtlasAxes axes = AtlasAxesOf(surface_, layout_, static_cast<int>(f));
      if (options_.field_in_world.empty()) {
        // the face frame's x axis, in the atlas frame
        field_in_chart_rad_.push_back(-layout_.faces[f].AtlasFrameAngle());
      } else {
        const Eigen::Vector3d& v = options_.field_in_world[f];
        field_in_chart_rad_.push_back(std::atan2(v.dot(axes.y), v.dot(axes.x)));
      }
    }
  }

  // T_c's unit: the mean cost of a cut between two unrelated texels of the
  // sample, |f(p) - g(p)| + |f(q) - g(q)| with f, g at random positions.
  double RandomPairCost() {
    const RotatedCopy& copy = rotated_.Copy(0);
    std::uniform_int_distribution<int> at(0, copy.side() - 1);
    double sum = 0;
    const int pairs = 512;
    for (int i = 0; i < pairs; ++i) {
      const int x0 = at(rng_), y0 = at(rng_), x1 = at(rng_), y1 = at(rng_);
      double d2 = 0;
      for (const cv::Mat& plane : copy.planes) {
        const double d = plane.at<float>(y0, x0) - plane.at<float>(y1, x1);
        d2 += d * d;
      }
      sum += 2 * std::sqrt(d2);
    }
    return sum / pairs;
  }

  // The unsynthesised sample with the most synthesised neighbours (paper 004
  // Fig. 4), the lowest index among equals.
  int MostConstrained() {
    while (true) {
      const auto [count, minus_s] = queue_.top();
      queue_.pop();
      const int s = -minus_s;
      if (!result_.lookups[static_cast<std::size_t>(s)].synthesised &&
          count == synthesised_neighbours_[static_cast<std::size_t>(s)])
        return s;
    }
  }

  // The hierarchical search: shrink r_w until the work image is flat enough and
  // the seam cheap enough. Returns the samples newly synthesised.
  std::size_t PlacePatchAt(int v) {
    int levels = options_.work_patch_levels;
    while (true) {
      const bool smallest = levels <= options_.min_work_patch_levels;
      WorkPatch patch = work_patches_.Build(v, levels);
      if (smallest && !patch.fits) work_patches_.TrimToCopySide(patch);
      TEXLUME_CHECK(patch.fits || !smallest, "the smallest work patch outgrew the sample");
      if (patch.fits && (patch.distortion <= options_.max_area_distortion || smallest)) {
        const std::size_t placed = TryPatch(patch, smallest, levels);
        if (placed > 0) return placed;
      }
      levels = std::max(options_.min_work_patch_levels,
                        static_cast<int>(std::floor(levels * options_.shrink)));
    }
  }

  // Features of sample s turned from its chart's frame into the work frame
  // (or back, with the opposite angle).
  void Turn(float* f, double chart_to_work_rad) const {
    synth::Unfolding turn;
    turn.rotation = Eigen::Rotation2Dd(chart_to_work_rad).toRotationMatrix();
    turn.coefficients_to_this = ptm::OrthonormalFrameRotation(-chart_to_work_rad);
    sample_.TurnFeatures(turn, f);
  }
  float* ValuesOf(int s) {
    return values_.data() + static_cast<std::size_t>(s) * static_cast<std::size_t>(features_);
  }
  bool Synthesised(int s) const {
    return given_[static_cast<std::size_t>(s)] ||
           result_.lookups[static_cast<std::size_t>(s)].synthesised;
  }

  // Patch matching, fitting and, below T_c (or at the smallest r_w), commit.
  std::size_t TryPatch(const WorkPatch& patch, bool smallest, int levels) {
    const int rotation = ChooseRotation(patch);
    const RotatedCopy& copy = rotated_.Copy(rotation);
    const Placement placement = MatchPlacement(patch, copy);
    const Fit fit = FitPatch(patch, copy, placement);
    const double mean_cost = fit.cut_links ? fit.seam_cost / fit.cut_links : 0.0;
    const bool cheap = mean_cost <= options_.seam_threshold * result_.stats.random_pair_cost;
    if (!cheap && !smallest && !options_.random_placement) return 0;
    result_.stats.forced += !cheap && !options_.random_placement;
    result_.stats.photo_patches += placement.by_photos;
    ++result_.stats.accepted_at_levels[levels];
    result_.stats.cut_links += fit.cut_links;
    result_.stats.seam_cost += fit.seam_cost;
    return Commit(patch, copy, fit);
  }

  // The sample's x axis along the patch's mean field orientation, or random.
  int ChooseRotation(const WorkPatch& patch) {
    if (options_.random_orientation)
      return std::uniform_int_distribution<int>(0, RotatedSample::kRotations - 1)(rng_);
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const PatchSample& p : patch.samples) {
      const int f = surface_.samples()[static_cast<std::size_t>(p.sample)].face;
      const double a = field_in_chart_rad_[static_cast<std::size_t>(f)] + p.chart_to_work_rad;
      mean += Eigen::Vector2d(std::cos(a), std::sin(a));
    }
    return RotatedSample::RotationNearest(std::atan2(mean.y(), mean.x()));
  }

  // Entire-patch matching against the synthesised part of the work image,
  // among the photos' best placements when an image term scores the patch; a
  // random placement when nothing constrains it.
  Placement MatchPlacement(const WorkPatch& patch, const RotatedCopy& copy) {
    std::vector<cv::Mat> planes;
    cv::Mat mask;
    SynthesisedFeatures(patch, planes, mask);
    const bool overlap = cv::countNonZero(mask) > 0;
    if (image_term_ && !options_.random_placement) {
      const PatchImageTerm::Score score = image_term_->Placements(
          patch.samples[0].sample, WorkImageSamples(patch), mask.size(), copy.rotation, rotated_);
      if (!score.rms.empty()) return AmongPhotosBest(score, copy, planes, mask, overlap);
    }
    if (overlap && !options_.random_placement) return MatchEntirePatch(copy, planes, mask);
    Placement random;
    random.rotation = copy.rotation;
    random.x = std::uniform_int_distribution<int>(0, copy.side() - patch.width)(rng_);
    random.y = std::uniform_int_distribution<int>(0, copy.side() - patch.height)(rng_);
    return random;
  }

  // Algorithm 2 of paper 003 on the work patch: of the image term's best
  // placements, the one whose overlap with the synthesised part costs least.
  Placement AmongPhotosBest(const PatchImageTerm::Score& score, const RotatedCopy& copy,
                            const std::vector<cv::Mat>& planes, const cv::Mat& mask,
                            bool overlap) const {
    const auto candidates = synth::BestPlacements(score.rms, score.stride, options_.image_top_k);
    TEXLUME_CHECK(!candidates.empty(), "an image term scored no placement");
    Placement best;
    best.rotation = copy.rotation;
    best.by_photos = true;
    std::size_t chosen = 0;
    if (overlap) {
      const cv::Mat costs = EntirePatchCosts(copy, planes, mask);
      chosen = synth::ClosestToNeighbours(
          candidates, [&](int x, int y) { return costs.at<float>(y, x); }, &best.cost);
    }
    best.x = candidates[chosen].second.x, best.y = candidates[chosen].second.y;
    return best;
  }

  std::vector<WorkImageSample> WorkImageSamples(const WorkPatch& patch) const {
    std::vector<WorkImageSample> samples;
    samples.reserve(patch.samples.size());
    for (const PatchSample& p : patch.samples) {
      const auto [x, y] = Pixel(patch, p);
      samples.push_back({p.sample, x, y, Synthesised(p.sample)});
    }
    return samples;
  }

  // The work image: the synthesised samples' features turned into the work
  // frame, and the mask of the pixels they cover.
  void SynthesisedFeatures(const WorkPatch& patch, std::vector<cv::Mat>& planes, cv::Mat& mask) {
    planes.resize(static_cast<std::size_t>(features_));
    for (cv::Mat& plane : planes) plane = cv::Mat::zeros(patch.height, patch.width, CV_32FC1);
    mask = cv::Mat::zeros(patch.height, patch.width, CV_32FC1);
    std::vector<float> f(static_cast<std::size_t>(features_));
    for (const PatchSample& p : patch.samples) {
      if (!Synthesised(p.sample)) continue;
      const auto [x, y] = Pixel(patch, p);
      if (mask.at<float>(y, x) > 0) continue;  // two samples on one pixel: the nearer to v
      std::copy_n(ValuesOf(p.sample), features_, f.data());
      Turn(f.data(), p.chart_to_work_rad);
      for (int c = 0; c < features_; ++c)
        planes[static_cast<std::size_t>(c)].at<float>(y, x) = f[static_cast<std::size_t>(c)];
      mask.at<float>(y, x) = 1.0f;
    }
  }

  static std::pair<int, int> Pixel(const WorkPatch& patch, const PatchSample& p) {
    return {
        std::clamp(static_cast<int>(std::lround(p.w.x() - patch.origin.x())), 0, patch.width - 1),
        std::clamp(static_cast<int>(std::lround(p.w.y() - patch.origin.y())), 0, patch.height - 1)};
  }

  struct Fit {
    std::vector<Eigen::Vector2d> copy_px;  ///< per patch sample
    std::vector<float> fresh;              ///< per patch sample, features in its chart's frame
    std::vector<bool> take_new;
    std::vector<std::array<std::size_t, 2>> links;  ///< patch-local (lo, hi), lo's sample < hi's
    std::size_t cut_links = 0;
    double seam_cost = 0;
  };

  // An old seam between two linked samples (Kwatra et al. 2003, §3.3): the
  // patches on either side when it was cut, and what each patch shows on the
  // other side (in that sample's chart frame).
  struct OldSeam {
    int patch_lo = -1, patch_hi = -1;
    std::vector<float> hi_patch_at_lo, lo_patch_at_hi;
  };
  static std::uint64_t LinkKey(int lo, int hi) {
    return (static_cast<std::uint64_t>(lo) << 32) | static_cast<std::uint32_t>(hi);
  }
  // The old seam on a link, when it is still there (both sides unchanged).
  const OldSeam* SeamOn(int lo, int hi) const {
    if (!options_.keep_old_seams) return nullptr;
    const auto it = old_seams_.find(LinkKey(lo, hi));
    if (it == old_seams_.end()) return nullptr;
    const OldSeam& seam = it->second;
    const bool current = result_.patch_of[static_cast<std::size_t>(lo)] == seam.patch_lo &&
                         result_.patch_of[static_cast<std::size_t>(hi)] == seam.patch_hi;
    return current ? &seam : nullptr;
  }
  double Distance(const float* a, const float* b) const {
    double d2 = 0;
    for (int c = 0; c < features_; ++c) d2 += std::pow(static_cast<double>(a[c]) - b[c], 2);
    return std::sqrt(d2);
  }

  // The copy's values at every sample of the patch, in the samples' chart frames.
  void FreshValues(const WorkPatch& patch, const RotatedCopy& copy, const Placement& placement,
                   Fit& fit) const {
    const std::size_t n = patch.samples.size(), nf = static_cast<std::size_t>(features_);
    fit.fresh.resize(n * nf);
    for (std::size_t i = 0; i < n; ++i) {
      const PatchSample& p = patch.samples[i];
      fit.copy_px.push_back(Eigen::Vector2d(placement.x, placement.y) + p.w - patch.origin +
                            Eigen::Vector2d(0.5, 0.5));
      float* f = fit.fresh.data() + i * nf;
      for (std::size_t c = 0; c < nf; ++c)
        f[c] = Bilinear(copy.planes[c], fit.copy_px[i].x(), fit.copy_px[i].y());
      Turn(f, -p.chart_to_work_rad);
    }
  }

  // Patch fitting (paper 004 §III-B after Kwatra et al. 2003): a minimum cut
  // over the patch's samples between the old values (A) and the copy's (B),
  // M(s, t, A, B) = |A(s) - B(s)| + |A(t) - B(t)|. Unsynthesised samples must
  // take B; synthesised ones next to synthesised samples outside the patch keep
  // A; an old seam on a link becomes a node between its two samples, tied to B
  // by the old seam's cost, so a new cut pays for what it keeps of it.
  Fit FitPatch(const WorkPatch& patch, const RotatedCopy& copy, const Placement& placement) {
    const std::size_t n = patch.samples.size(), nf = static_cast<std::size_t>(features_);
    Fit fit;
    FreshValues(patch, copy, placement, fit);
    const auto fresh = [&](std::size_t i) { return fit.fresh.data() + i * nf; };
    const auto old = [&](std::size_t i) { return ValuesOf(patch.samples[i].sample); };
    std::vector<double> change(n, 0.0);  // |A(s) - B(s)|, 0 where A is not synthesised
    for (std::size_t i = 0; i < n; ++i)
      if (Synthesised(patch.samples[i].sample)) change[i] = Distance(old(i), fresh(i));
    std::vector<std::pair<std::size_t, const OldSeam*>> seams;  // link index, seam
    for (std::size_t i = 0; i < n; ++i)
      for (const int nb : surface_.Neighbours(patch.samples[i].sample)) {
        const auto it = patch.local.find(nb);
        if (it == patch.local.end() || nb < patch.samples[i].sample) continue;
        fit.links.push_back({i, static_cast<std::size_t>(it->second)});
        if (const OldSeam* seam = SeamOn(patch.samples[i].sample, nb))
          seams.emplace_back(fit.links.size() - 1, seam);
      }
    synth::MinCut cut(static_cast<int>(n + seams.size()),
                      static_cast<int>(fit.links.size() + 2 * seams.size()));
    std::vector<std::array<double, 2>> seam_costs(fit.links.size(),
                                                  {0.0, 0.0});  // M(A_lo,B), M(A_hi,B)
    std::size_t next_seam = 0;
    for (std::size_t k = 0; k < fit.links.size(); ++k) {
      const auto [i, j] = fit.links[k];
      if (next_seam < seams.size() && seams[next_seam].first == k) {
        const OldSeam& seam = *seams[next_seam].second;
        const int node = static_cast<int>(n + next_seam++);
        const double lo_b = change[i] + Distance(seam.lo_patch_at_hi.data(), fresh(j));
        const double hi_b = Distance(seam.hi_patch_at_lo.data(), fresh(i)) + change[j];
        const double lo_hi = Distance(old(i), seam.hi_patch_at_lo.data()) +
                             Distance(seam.lo_patch_at_hi.data(), old(j));
        cut.Link(static_cast<int>(i), node, lo_b);
        cut.Link(node, static_cast<int>(j), hi_b);
        cut.Terminals(node, lo_hi, 0.0);
        seam_costs[k] = {lo_b, hi_b};
      } else {
        cut.Link(static_cast<int>(i), static_cast<int>(j), change[i] + change[j]);
        seam_costs[k] = {change[i] + change[j], change[i] + change[j]};
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const int s = patch.samples[i].sample;
      bool keep = false;
      for (const int nb : surface_.Neighbours(s))
        keep = keep || (!patch.local.count(nb) && Synthesised(s) && Synthesised(nb));
      if (!Synthesised(s))
        cut.Terminals(static_cast<int>(i), kForced, 0.0);  // must take B
      else if (keep || given_[static_cast<std::size_t>(s)])
        cut.Terminals(static_cast<int>(i), 0.0, kForced);  // must keep A
    }
    cut.Solve();
    fit.take_new.resize(n);
    for (std::size_t i = 0; i < n; ++i) fit.take_new[i] = !cut.IsA(static_cast<int>(i));
    for (std::size_t k = 0; k < fit.links.size(); ++k) {
      const auto [i, j] = fit.links[k];
      if (fit.take_new[i] == fit.take_new[j]) continue;
      ++fit.cut_links;  // the new seam lies between B and the kept side's patch
      fit.seam_cost += fit.take_new[i] ? seam_costs[k][1] : seam_costs[k][0];
    }
    return fit;
  }

  // The seams the accepted cut leaves, remembered with what each side's patch
  // shows across them (only where both values are known).
  void RememberSeams(const WorkPatch& patch, const Fit& fit, int id) {
    const std::size_t nf = static_cast<std::size_t>(features_);
    for (const auto& [i, j] : fit.links) {
      if (fit.take_new[i] == fit.take_new[j]) continue;
      const std::size_t fresh_side = fit.take_new[i] ? i : j, kept = fit.take_new[i] ? j : i;
      const int s_new = patch.samples[fresh_side].sample, s_kept = patch.samples[kept].sample;
      // The kept side's patch at the new sample: its old value when that patch
      // was there, or what an old seam on this link remembers of it.
      if (!Synthesised(s_new)) continue;
      const float* kept_at_new = nullptr;
      if (result_.patch_of[static_cast<std::size_t>(s_new)] ==
          result_.patch_of[static_cast<std::size_t>(s_kept)]) {
        kept_at_new = ValuesOf(s_new);
      } else if (const OldSeam* old = SeamOn(std::min(s_new, s_kept), std::max(s_new, s_kept))) {
        kept_at_new = (s_new < s_kept ? old->hi_patch_at_lo : old->lo_patch_at_hi).data();
      } else {
        continue;
      }
      const float* new_at_kept = fit.fresh.data() + kept * nf;
      OldSeam seam;
      const bool new_is_lo = s_new < s_kept;
      seam.patch_lo = new_is_lo ? id : result_.patch_of[static_cast<std::size_t>(s_kept)];
      seam.patch_hi = new_is_lo ? result_.patch_of[static_cast<std::size_t>(s_kept)] : id;
      seam.hi_patch_at_lo.assign(new_is_lo ? kept_at_new : new_at_kept,
                                 (new_is_lo ? kept_at_new : new_at_kept) + nf);
      seam.lo_patch_at_hi.assign(new_is_lo ? new_at_kept : kept_at_new,
                                 (new_is_lo ? new_at_kept : kept_at_new) + nf);
      old_seams_[LinkKey(std::min(s_new, s_kept), std::max(s_new, s_kept))] = std::move(seam);
    }
  }

  std::size_t Commit(const WorkPatch& patch, const RotatedCopy& copy, const Fit& fit) {
    const int id = static_cast<int>(result_.stats.patches++);
    RememberSeams(patch, fit, id);
    const std::size_t nf = static_cast<std::size_t>(features_);
    std::size_t fresh = 0;
    for (std::size_t i = 0; i < patch.samples.size(); ++i) {
      if (!fit.take_new[i]) continue;
      const PatchSample& p = patch.samples[i];
      std::copy_n(fit.fresh.data() + i * nf, nf, ValuesOf(p.sample));
      SampleLookup& lookup = result_.lookups[static_cast<std::size_t>(p.sample)];
      const Eigen::Vector2d sample_px = rotated_.SamplePosition(copy.rotation, fit.copy_px[i]);
      lookup.sample_px = sample_px.cast<float>();
      lookup.angle_rad = static_cast<float>(copy.angle_rad - p.chart_to_work_rad);
      result_.patch_of[static_cast<std::size_t>(p.sample)] = id;
      if (lookup.synthesised) continue;
      lookup.synthesised = true;
      ++fresh;
      for (const int nb : surface_.Neighbours(p.sample)) {
        if (Synthesised(nb)) continue;
        queue_.emplace(++synthesised_neighbours_[static_cast<std::size_t>(nb)], -nb);
      }
    }
    return fresh;
  }

  const DenseSurface& surface_;
  const atlas::AtlasLayout& layout_;
  const synth::MaterialSample& sample_;
  const QuiltOptions options_;
  RotatedSample rotated_;
  const WorkPatchBuilder work_patches_;
  const int features_;
  PatchImageTerm* image_term_;
  std::mt19937_64 rng_;
  std::vector<double> field_in_chart_rad_;
  std::vector<float> values_;  ///< per sample, its features in its chart's frame
  std::vector<int> synthesised_neighbours_;
  std::vector<bool> given_;  ///< per sample: given before quilting (GivenSamples)
  std::priority_queue<std::pair<int, int>> queue_;  ///< (count, -sample), stale entries skipped
  std::unordered_map<std::uint64_t, OldSeam> old_seams_;  ///< by LinkKey(lo, hi)
  QuiltResult result_;
};

}  // namespace

double SeamShare(const QuiltStats& stats) {
  return stats.cut_links && stats.random_pair_cost > 0
             ? stats.seam_cost / static_cast<double>(stats.cut_links) / stats.random_pair_cost
             : 0.0;
}

QuiltResult QuiltSurface(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                         const synth::MaterialSample& sample, const QuiltOptions& options,
                         const ProgressCallback& progress, const GivenSamples* given,
                         PatchImageTerm* image_term) {
  options.Check();
  if (!options.field_in_world.empty() && options.field_in_world.size() != layout.faces.size())
    throw std::invalid_argument("QuiltSurface: one field vector per face");
  if (surface.size() == 0) return {};
  return SurfaceQuilter(surface, layout, sample, options, given, image_term).Run(progress);
}

}  // namespace texlume::quilt

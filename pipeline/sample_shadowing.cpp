#include "pipeline/sample_shadowing.h"

#include <algorithm>
#include <numbers>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "ptm/shadowed_fit.h"

namespace texlume::pipeline {
namespace {

// The PTM sample's self-shadowing (SampleShadowingStage's constructor).
ptm::SelfShadowing ReadSampleShadowing(const std::filesystem::path& file, const Sample& sample) {
  if (!sample.colour.empty())
    throw InputError(file.string(), "a horizon map goes with a PTM sample, not a colour photo");
  return ptm::ReadSelfShadowingExr(file, sample.ptm.width, sample.ptm.height, "the sample");
}

// SampleShadowingStage::ShadowAtlases at `relief_gain` (<= 0: matched); returns each
// atlas's relief gain.
std::vector<double> ShadowModelAtlases(const ptm::SelfShadowing& sample,
                                       const std::filesystem::path& file, double relief_gain,
                                       model::TexturedModel& model,
                                       const ProgressCallback& progress) {
  // Every atlas's horizon is kept (4 bytes a sector), and written through planes and
  // an interleaved copy (twice that again); one atlas's heights and normals at a time.
  // The GLB keeps every atlas's 16 horizon bytes a texel as PNGs (at most that) until
  // it is written, each made from 16 quantised bytes a texel
  // (model::EncodeHorizonTextures).
  constexpr double kGlbHorizonBytes = 16.0;
  double kept_texels = 0.0, largest = 0.0;
  for (const ptm::Ptm& atlas : model.atlases) {
    kept_texels += static_cast<double>(atlas.NumTexels());
    largest = std::max(largest, static_cast<double>(atlas.NumTexels()));
  }
  RequireMemory(kept_texels * (4.0 * sample.horizon.sectors + kGlbHorizonBytes) +
                    largest * (8.0 * sample.horizon.sectors + 64.0 + kGlbHorizonBytes),
                "the atlases' horizon maps", file.string());
  const double sample_loss = relief_gain > 0.0 ? 0.0 : ptm::LowLightShadowLoss(sample, {});
  std::vector<double> relief_gains;
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    if (progress) progress("the atlases' horizons", a, model.atlases.size());
    ptm::SelfShadowing atlas = ptm::ShadowingOfPtm(model.atlases[a], sample);
    relief_gains.push_back(relief_gain > 0.0
                               ? ptm::ScaleRelief(atlas, relief_gain)
                               : ptm::MatchLowLightShadowLoss(
                                     atlas, ptm::CoveredTexels(model.atlases[a]), sample_loss));
    model.shadowing.push_back(std::move(atlas));
  }
  return relief_gains;
}

}  // namespace

SampleShadowingStage::SampleShadowingStage(const SynthJobOptions& options, const Sample& sample)
    : options_(options), shadowing_(ReadSampleShadowing(options.sample_horizon_file, sample)) {
  if (!options_.shadowed_synthesis) return;
  // The horizon's elevations and their squares join the sample's relit planes
  // (synth::PtmSample), kept at full size and reduced at each density level the photos
  // ask for (about 3.4 times the full size in all, with a margin: 4.5).
  const ptm::HorizonMap& h = shadowing_.horizon;
  RequireMemory(2.0 * h.sectors * static_cast<double>(h.NumTexels()) * 4.0 * 4.5,
                "the sample's horizon planes (--shadowed-synthesis)",
                options_.sample_horizon_file.string());
}

const ptm::SelfShadowing* SampleShadowingStage::ForSynthesis() const {
  return options_.shadowed_synthesis ? &shadowing_ : nullptr;
}

void SampleShadowingStage::ShadowAtlases(model::TexturedModel& model,
                                         const ProgressCallback& progress) {
  atlas_relief_gains_ = ShadowModelAtlases(shadowing_, options_.sample_horizon_file,
                                           options_.atlas_relief_gain, model, progress);
}

nlohmann::json SampleShadowingStage::Record() const {
  return {{"file", options_.sample_horizon_file.string()},
          {"height_scale", shadowing_.height_scale},
          {"shadow_floor", shadowing_.shadow_floor},
          {"penumbra_deg", shadowing_.penumbra_rad * 180.0 / std::numbers::pi},
          {"in_synthesis", options_.shadowed_synthesis},
          {"atlas_relief_gain", options_.atlas_relief_gain > 0.0
                                    ? nlohmann::json(options_.atlas_relief_gain)
                                    : nlohmann::json("auto")},
          {"atlas_relief_gains", atlas_relief_gains_}};
}

}  // namespace texlume::pipeline

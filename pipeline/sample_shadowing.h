#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/progress.h"
#include "model/model_io.h"
#include "pipeline/synth_job.h"
#include "ptm/horizon.h"

namespace texlume::pipeline {

/// `texlume synth --sample-horizon FILE`: the PTM sample's self-shadowing (the
/// horizon map `texlume fit --horizon` wrote). Throws InputError naming the file
/// for a colour sample, a file that is not a horizon map, or another size than
/// the sample's.
ptm::SelfShadowing ReadSampleShadowing(const std::filesystem::path& file, const Sample& sample);

/// Per atlas of `model`, the relief's horizon from the atlas's own normals at the
/// sample's height scale (ptm::ShadowingOfPtm), its relief then times `relief_gain`,
/// or (`relief_gain` <= 0) scaled so that it takes from low lights the sample's share
/// of light (ptm::MatchLowLightShadowLoss, over the texels its charts cover), into
/// `model.shadowing`. Returns each atlas's relief gain. Refused up front
/// (memory_budget.h, naming `file`) when the horizon maps would not fit.
std::vector<double> ShadowModelAtlases(const ptm::SelfShadowing& sample,
                                       const std::filesystem::path& file, double relief_gain,
                                       model::TexturedModel& model,
                                       const ProgressCallback& progress);

/// The synth job's `--sample-horizon` steps, one method each: the sample's horizon
/// read (with the memory `--shadowed-synthesis` needs, refused up front), the
/// shadowing the synthesis relights the sample with, the atlases' horizons, and
/// the manifest's record of them.
class SampleShadowingStage {
 public:
  /// Reads options.sample_horizon_file (ReadSampleShadowing); `options` must outlive
  /// the stage.
  SampleShadowingStage(const SynthJobOptions& options, const Sample& sample);
  /// The sample's self-shadowing with --shadowed-synthesis, else null.
  const ptm::SelfShadowing* ForSynthesis() const;
  /// ShadowModelAtlases with the options' relief gain.
  void ShadowAtlases(model::TexturedModel& model, const ProgressCallback& progress);
  /// The manifest's `inputs.sample_horizon`.
  nlohmann::json Record() const;

 private:
  const SynthJobOptions& options_;
  ptm::SelfShadowing shadowing_;
  std::vector<double> atlas_relief_gains_;  ///< per atlas, once ShadowAtlases ran
};

}  // namespace texlume::pipeline

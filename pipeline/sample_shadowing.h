#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/progress.h"
#include "model/model_io.h"
#include "pipeline/synth_job.h"
#include "ptm/horizon.h"

namespace texlume::pipeline {

/// The synth job's `--sample-horizon` steps, one method each: the sample's horizon
/// read (with the memory `--shadowed-synthesis` needs, refused up front), the
/// shadowing the synthesis relights the sample with, the atlases' horizons, and
/// the manifest's record of them.
class SampleShadowingStage {
 public:
  /// Reads options.sample_horizon_file (the horizon map `texlume fit --horizon`
  /// wrote); `options` must outlive the stage. Throws InputError naming the file for
  /// a colour sample, a file that is not a horizon map, or another size than the
  /// sample's.
  SampleShadowingStage(const SynthJobOptions& options, const Sample& sample);
  /// The sample's self-shadowing with --shadowed-synthesis, else null.
  const ptm::SelfShadowing* ForSynthesis() const;
  /// Per atlas of `model`, the relief's horizon from the atlas's own normals at the
  /// sample's height scale (ptm::ShadowingOfPtm), its relief then times
  /// --atlas-relief-gain, or (without it) scaled so that it takes from low lights the
  /// sample's share of light (ptm::MatchLowLightShadowLoss, over the texels its
  /// charts cover), into `model.shadowing`. Refused up front (memory_budget.h, naming
  /// the horizon file) when the horizon maps would not fit.
  void ShadowAtlases(model::TexturedModel& model, const ProgressCallback& progress);
  /// The manifest's `inputs.sample_horizon`.
  nlohmann::json Record() const;

 private:
  const SynthJobOptions& options_;
  ptm::SelfShadowing shadowing_;
  std::vector<double> atlas_relief_gains_;  ///< per atlas, once ShadowAtlases ran
};

}  // namespace texlume::pipeline

#pragma once

#include <filesystem>
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

}  // namespace texlume::pipeline

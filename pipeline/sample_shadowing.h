#pragma once

#include <filesystem>

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
/// sample's height scale (ptm::ShadowingOfPtm), into `model.shadowing`. Refused up
/// front (memory_budget.h, naming `file`) when the horizon maps would not fit.
void ShadowModelAtlases(const ptm::SelfShadowing& sample, const std::filesystem::path& file,
                        model::TexturedModel& model, const ProgressCallback& progress);

}  // namespace texlume::pipeline

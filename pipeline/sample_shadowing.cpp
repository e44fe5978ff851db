#include "pipeline/sample_shadowing.h"

#include <algorithm>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "ptm/shadowed_fit.h"

namespace texlume::pipeline {

ptm::SelfShadowing ReadSampleShadowing(const std::filesystem::path& file, const Sample& sample) {
  if (!sample.colour.empty())
    throw InputError(file.string(), "a horizon map goes with a PTM sample, not a colour photo");
  return ptm::ReadSelfShadowingExr(file, sample.ptm.width, sample.ptm.height, "the sample");
}

void ShadowModelAtlases(const ptm::SelfShadowing& sample, const std::filesystem::path& file,
                        model::TexturedModel& model, const ProgressCallback& progress) {
  // Every atlas's horizon is kept (4 bytes a sector), and written through planes and
  // an interleaved copy (twice that again); one atlas's heights and normals at a time.
  double kept_texels = 0.0, largest = 0.0;
  for (const ptm::Ptm& atlas : model.atlases) {
    kept_texels += static_cast<double>(atlas.NumTexels());
    largest = std::max(largest, static_cast<double>(atlas.NumTexels()));
  }
  RequireMemory(
      kept_texels * 4.0 * sample.horizon.sectors + largest * (8.0 * sample.horizon.sectors + 64.0),
      "the atlases' horizon maps", file.string());
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    if (progress) progress("the atlases' horizons", a, model.atlases.size());
    model.shadowing.push_back(ptm::ShadowingOfPtm(model.atlases[a], sample));
  }
}

}  // namespace texlume::pipeline

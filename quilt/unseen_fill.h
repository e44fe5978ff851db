#pragma once

#include <cstddef>
#include <vector>

#include "atlas/atlas.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "quilt/dense_surface.h"
#include "quilt/surface_quilting.h"
#include "synth/btf_sample.h"
#include "synth/mesh_btf.h"
#include "synth/mesh_synthesis.h"

// The main job's `--fill-unseen graphcut` (issue 32): the faces no photo sees
// are quilted by the graph-cut engine (paper 004 §III) instead of taking the
// per-triangle engine's overlap-only placement. The faces the photos placed are
// given to the quilt as they are (with their photo corrections), so the quilt
// grows out from them and its cuts run inside the unseen faces.

namespace texlume::quilt {

struct UnseenFillOptions {
  QuiltOptions quilt;
  /// The charts the dense surface is sampled on: the main job's own, so that
  /// its atlases hold one texel per dense sample.
  atlas::AtlasOptions atlas;
};

struct UnseenFillSummary {
  std::size_t faces = 0;          ///< faces filled (placed by no photo)
  std::vector<bool> filled;       ///< per face: filled
  std::size_t samples = 0;        ///< dense samples in them, quilted
  std::size_t given_samples = 0;  ///< dense samples of the faces the photos placed
  QuiltStats stats;
  double seconds = 0;  ///< layout, dense surface, quilting
};

/// The dense samples of `surface` that lie in the faces the photos placed
/// (TrianglePatch::source kPhotos), with the features their patches show there
/// (the orthonormal coefficients of MeshSynthesis::SamplePatch: photo
/// corrections and detail transfer included) turned from the face frame into
/// the chart's atlas frame: the features of a synth::PtmSample of the
/// synthesis's sample planes.
GivenSamples SamplesOfPhotoFaces(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                                 const synth::MeshSynthesis& synthesis);

/// Quilts the faces of `synthesis` that no photo placed and installs the result
/// as their values (MeshSynthesis::fill): every reader of their patches (the
/// blending across edges, the atlases, the report) then sees the quilt. The
/// quilted sample is the synthesis's own (`sample_planes`: a PTM sample, or a
/// colour sample's Lambertian PTM), matched on its orthonormal coefficients.
/// Nothing changes when every face was placed from photos.
UnseenFillSummary FillUnseenFaces(const mesh::TriangleMesh& mesh, synth::MeshSynthesis& synthesis,
                                  const UnseenFillOptions& options,
                                  const ProgressCallback& progress = {});

/// The same for a BTF synthesis: the sample's geometry maps are matched (the
/// given ones where each placed face's lookup reads, seams included), and the
/// quilt's lookups become the filled faces' (BtfMeshSynthesis::fill), with
/// photo-consistency factors of 1.
UnseenFillSummary FillUnseenFaces(const mesh::TriangleMesh& mesh,
                                  synth::BtfMeshSynthesis& synthesis,
                                  const synth::BtfSample& sample, const UnseenFillOptions& options,
                                  const ProgressCallback& progress = {});

}  // namespace texlume::quilt

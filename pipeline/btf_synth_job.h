#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "atlas/btf_atlas.h"
#include "btf/btf.h"
#include "core/progress.h"
#include "pipeline/synth_job.h"
#include "ptm/ptm.h"
#include "synth/mesh_btf.h"

namespace texlume::pipeline {

/// Inputs and settings of `texlume synth --btf DIR`.
struct BtfSynthJobOptions {
  /// Paths, atlas, visibility, subdivision and report settings; `sample_file`
  /// is ignored and `synthesis.sample_texel_size` unused.
  pipeline::SynthJobOptions job;
  /// A BTF capture folder (btf.json) or a factorisation (btf_svd.json).
  std::filesystem::path btf;
  /// Components kept when factorising a capture (paper 004: 40).
  int components = 40;
  /// sample_texel_size 0 = the capture's texel size.
  synth::BtfMeshSynthesisOptions synthesis;

  /// Throws OptionError when a path is missing or a setting is out of range
  /// (the synthesis settings with the texel size still to be resolved).
  void Check() const;
};

struct BtfSynthJobSummary : pipeline::SynthCounts {
  quilt::UnseenFillSummary unseen_fill;  ///< the graph-cut fill (FillUnseen::kGraphcut)
  std::size_t seam_edges = 0;
  double seam_cost_per_link = 0, edge_cost_per_link = 0;
  double seconds_factorise = 0, seconds_synthesis = 0, seconds_seams = 0, seconds_atlas = 0,
         seconds_preview = 0, seconds_export = 0, seconds_total = 0;
};

/// The main job with a BTF sample: reads the inputs (pipeline::LoadSynthInputs),
/// factorises the capture, synthesises (synth::SynthesizeMeshBtf), lays out and bakes
/// the atlases, and writes a model folder: everything a PTM model folder holds
/// (the PTM preview as its atlases, the baselines `texlume render` draws), plus
/// `btf/` (the factorisation: geometry_maps.exr, appearance.bin, btf_svd.json),
/// `btf_atlas_K.exr` (per texel its sample position and angle) and the baked
/// geometry-map atlases `btf_geometry_K_P.png` (docs/btf.md). Nothing is
/// written on error.
BtfSynthJobSummary RunBtfSynthJob(const BtfSynthJobOptions& options,
                                  const ProgressCallback& progress = {});

}  // namespace texlume::pipeline

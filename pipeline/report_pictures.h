#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/progress.h"
#include "mesh/mesh.h"
#include "model/model_io.h"
#include "ptm/ptm.h"
#include "render/view_pictures.h"
#include "report/report.h"
#include "sfm/lights.h"

namespace texlume::pipeline {

/// What a job's report draws: the model with its baselines, the sample, and the
/// views to draw it from (the synth job: photo views; the demo: held-out views).
struct ReportScene {
  const model::TexturedModel* model = nullptr;  ///< required
  Eigen::Vector3f flat_albedo = Eigen::Vector3f::Constant(0.5f);
  std::vector<cv::Mat> baked;              ///< per atlas (display RGB); empty = no baked column
  const ptm::Ptm* sample = nullptr;        ///< null = no sample section
  std::vector<render::PictureView> views;  ///< at most `max_views` are drawn, evenly spread
  int max_views = 4;
  int picture_width = 300;  ///< pixels; views are drawn at (at most) this width
  int sweep_frames = 8;     ///< light-sweep frames of the first drawn view (0 = none)
  int sweep_width = 160;
  double light_elevation_deg = 40.0;  ///< of the sweep's and the sample's lights
  int sample_width = 200;             ///< the sample relit at (at most) this width

  /// Throws OptionError when a count or size is out of range.
  void Check() const;
};

/// `count` views around a mesh for a report without photos: cameras on a ring
/// 25 degrees above the bounding box centre's horizon (world +z up), at three
/// times its half diagonal, the box filling about 80 % of the picture's height,
/// each lit by one directional light from above the camera's left shoulder.
std::vector<render::PictureView> ViewsAroundMesh(const mesh::TriangleMesh& mesh, int count,
                                                 int width, int height);

/// Lights seen by the model (directional as they are, point lights from the mesh's
/// bounding box centre) on the hemisphere of the model's orientation: up as the photos
/// were taken (sfm::OrientationFromCameras), azimuth 0 toward the photos' side.
report::LightPlot LightPlotOfModel(const std::string& title,
                                   const std::vector<std::vector<sfm::ObjectLight>>& lights,
                                   const model::TexturedModel& model);

/// An RTI capture's lights (.lp: x right, y up the sample, z out of it).
report::LightPlot CaptureLightPlot(const std::vector<Eigen::Vector3d>& lights);

/// Renders the report's pictures into `report` (sample_relit, views,
/// views_total, sweep): the model in its own shading and the flat (and baked)
/// baselines from each picked view, measured against the view's reference.
/// Throws InputError naming a reference or mask that does not match its
/// camera.
void DrawReportPictures(const ReportScene& scene, report::ReportInputs& report,
                        const ProgressCallback& progress = {});

}  // namespace texlume::pipeline

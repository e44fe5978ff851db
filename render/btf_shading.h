#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/btf_model.h"
#include "render/model_render.h"
#include "sfm/lights.h"

namespace texlume::render {

/// The BTF model's display RGB at one ray hit: the nearest atlas texel's sample
/// position moved by the hit's offset from it, view and light directions in the
/// atlas frame (the renderer's smooth frame) turned into the sample frame by the
/// texel's angle, f = sum_lights I sum_i g_i(x) p_i(v, l) (g bilinear in the
/// sample; p interpolated over the direction grid), each light's term times the
/// light response's factor at its elevation, plus the response's ambient times
/// the value under a unit zenith light; times the texel's photo-consistency
/// factors, then sRGB.
Eigen::Vector3f ShadeBtf(const model::BtfModel& model, const ModelRenderer::SurfaceSample& sample,
                         const std::vector<sfm::ObjectLight>& lights,
                         const ptm::LightResponse& response);
/// The renderer's model's light response applies.

/// A BTF model folder's views: the model's ray caster shading every hit with
/// ShadeBtf (paper 004's lookup), `samples_per_axis`^2 rays per pixel.
RenderedView RenderBtf(const ModelRenderer& renderer, const model::BtfModel& btf,
                       const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                       const std::vector<sfm::ObjectLight>& lights, int samples_per_axis);

}  // namespace texlume::render

#pragma once

#include <filesystem>

#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"

namespace texlume::testing {

/// The small synthetic object scene the mesh tests share: 12 photos of 320 x
/// 240 (focal 300 px), a 128-texel material capture under 24 lights with
/// texels of 0.004 world units, no held-out capture lights, no BTF, no surface
/// photos. Callers set the rest (held-out views, relief, BTF).
inline datasets::SceneOptions SmallObjectScene(datasets::SceneShape shape,
                                               datasets::MaterialKind kind) {
  datasets::SceneOptions o;
  o.shape = shape;
  o.material.kind = kind;
  o.material.texel_size = 0.004;
  o.num_images = 12;
  o.image_width = 320;
  o.image_height = 240;
  o.focal_px = 300;
  o.capture_size = 128;
  o.num_capture_lights = 24;
  o.num_held_out_capture_lights = 0;
  o.write_btf = false;
  o.write_surface = false;
  return o;
}

/// The sample PTM fitted to a generated scene's material capture.
inline ptm::Ptm FitSceneSample(const std::filesystem::path& scene_dir) {
  const std::filesystem::path capture = scene_dir / "material/capture";
  const ptm::RtiCapture rti = ptm::ReadRtiCapture(capture / "lights.lp", capture);
  return ptm::FitPtmFromFiles(rti.files, rti.lights, {}).ptm;
}

}  // namespace texlume::testing

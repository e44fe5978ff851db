// The main job's time against mesh size (issue 6): the default stone sphere
// scene, its coarse mesh (1280 triangles) split 1-to-4 and put back on the
// sphere (5120, 20480), synthesised, blended and packed in both atlas modes.
// Run: build/bench/mesh_synth_bench [--levels N]
// Prints per size: visibility, synthesis, atlas seconds, ms per triangle, the
// ratio of synthesis time to the smallest mesh's, occupancy of both modes.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "atlas/atlas.h"
#include "datasets_synthetic/scene.h"
#include "mesh/mesh.h"
#include "pipeline/synth_job.h"
#include "ptm/fit.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"
#include "sfm/visibility.h"
#include "synth/mesh_synthesis.h"

using namespace texlume;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  int levels = 3;
  for (int i = 1; i + 1 < argc; i += 2)
    if (!std::strcmp(argv[i], "--levels")) levels = std::atoi(argv[i + 1]);
  const fs::path work = fs::temp_directory_path() / "texlume_mesh_synth_bench";
  datasets::SceneOptions scene;
  scene.write_btf = false;
  scene.write_surface = false;
  scene.num_held_out_views = 0;
  if (!fs::exists(work / "object/lights.json")) datasets::GenerateScene(scene, work);
  const ptm::RtiCapture rti =
      ptm::ReadRtiCapture(work / "material/capture/lights.lp", work / "material/capture");
  const ptm::Ptm sample = ptm::FitPtmFromFiles(rti.files, rti.lights, {}).ptm;
  const sfm::Reconstruction reconstruction = sfm::ReadModel(work / "object/sparse").reconstruction;
  const sfm::ObjectLights lights = sfm::ReadObjectLightsFile(work / "object/lights.json");
  std::vector<synth::MeshPhoto> photos;
  for (const auto& [id, image] : reconstruction.images) {
    synth::MeshPhoto p;
    p.image_id = id;
    p.name = image.name;
    p.pixels = PhotoPixels(ReadPhotoRgb(work / "object/images" / image.name));
    p.lights = lights.at(image.name);
    photos.push_back(p);
  }
  mesh::TriangleMesh mesh = mesh::LoadMesh(work / "object/mesh.ply").mesh;
  double base_synthesis = 0;
  for (int level = 0; level < levels; ++level) {
    if (level > 0) {
      mesh = mesh::SubdivideMidpoint(mesh);
      for (auto& v : mesh.vertices) v.normalize();  // back on the unit sphere
    }
    auto t0 = std::chrono::steady_clock::now();
    const sfm::VisibilityResult visibility = sfm::ComputeVisibility(mesh, reconstruction);
    const double seconds_visibility =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    synth::MeshSynthesisOptions o;
    o.sample_texel_size = scene.material.texel_size;
    const synth::MeshSynthesis s =
        synth::SynthesizeMeshPtm(mesh, reconstruction, visibility, photos, sample, o);
    if (level == 0) base_synthesis = s.seconds_synthesis;
    atlas::AtlasOptions charts, boxes;
    boxes.mode = atlas::AtlasMode::kPerTriangle;
    const atlas::Atlases a_charts = atlas::BuildAtlases(mesh, s, charts);
    const atlas::Atlases a_boxes = atlas::BuildAtlases(mesh, s, boxes);
    std::printf(
        "%6zu triangles: visibility %.2f s, synthesis %.2f s (%.2f ms per triangle, %.2fx the "
        "1280-triangle time), atlas %.2f s (charts) / %.2f s (boxes); occupancy charts %.3f in "
        "%zu atlas(es), %d charts; per triangle %.3f in %zu atlas(es)\n",
        mesh.faces.size(), seconds_visibility, s.seconds_synthesis,
        1e3 * s.seconds_synthesis / mesh.faces.size(), s.seconds_synthesis / base_synthesis,
        a_charts.seconds, a_boxes.seconds, a_charts.occupancy, a_charts.ptms.size(),
        a_charts.num_charts, a_boxes.occupancy, a_boxes.ptms.size());
  }
  return 0;
}

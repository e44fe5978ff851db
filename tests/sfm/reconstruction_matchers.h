#pragma once

#include <gtest/gtest.h>

#include "datasets_synthetic/object_scene.h"
#include "sfm/reconstruction.h"

namespace texlume::sfm {

/// Expects two models to hold the same cameras, images and points, with poses,
/// parameters and coordinates equal within `tolerance`.
inline void ExpectSameReconstruction(const Reconstruction& a, const Reconstruction& b,
                                     double tolerance = 0.0) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  ASSERT_EQ(a.images.size(), b.images.size());
  ASSERT_EQ(a.points3d.size(), b.points3d.size());
  for (const auto& [id, ca] : a.cameras) {
    ASSERT_TRUE(b.cameras.count(id)) << "camera " << id;
    const Camera& cb = b.cameras.at(id);
    EXPECT_EQ(ca.model, cb.model);
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    ASSERT_EQ(ca.params.size(), cb.params.size());
    for (std::size_t i = 0; i < ca.params.size(); ++i) {
      EXPECT_NEAR(ca.params[i], cb.params[i], tolerance * std::max(1.0, std::abs(ca.params[i])));
    }
  }
  for (const auto& [id, ia] : a.images) {
    ASSERT_TRUE(b.images.count(id)) << "image " << id;
    const Image& ib = b.images.at(id);
    EXPECT_EQ(ia.name, ib.name);
    EXPECT_EQ(ia.camera_id, ib.camera_id);
    EXPECT_NEAR(ia.cam_from_world.rotation.angularDistance(ib.cam_from_world.rotation), 0.0,
                std::max(tolerance, 1e-12));
    EXPECT_LE((ia.cam_from_world.translation - ib.cam_from_world.translation).norm(),
              tolerance * std::max(1.0, ia.cam_from_world.translation.norm()));
    ASSERT_EQ(ia.points2d.size(), ib.points2d.size());
    for (std::size_t i = 0; i < ia.points2d.size(); ++i) {
      EXPECT_LE((ia.points2d[i].xy - ib.points2d[i].xy).norm(), tolerance * 1e3);
      EXPECT_EQ(ia.points2d[i].point3d_id, ib.points2d[i].point3d_id);
    }
  }
  for (const auto& [id, pa] : a.points3d) {
    ASSERT_TRUE(b.points3d.count(id)) << "point " << id;
    const Point3D& pb = b.points3d.at(id);
    EXPECT_LE((pa.xyz - pb.xyz).norm(), tolerance * std::max(1.0, pa.xyz.norm()));
    EXPECT_EQ(pa.rgb, pb.rgb);
    EXPECT_NEAR(pa.error, pb.error, tolerance * std::max(1.0, std::abs(pa.error)));
    ASSERT_EQ(pa.track.size(), pb.track.size());
    for (std::size_t i = 0; i < pa.track.size(); ++i) {
      EXPECT_EQ(pa.track[i].image_id, pb.track[i].image_id);
      EXPECT_EQ(pa.track[i].point2d_idx, pb.track[i].point2d_idx);
    }
  }
}

/// A model with one camera of every COLMAP model, images spread over them, and
/// sparse points with tracks, from the synthetic generator.
inline Reconstruction MakeTestReconstruction(std::uint32_t seed = 3) {
  datasets::ObjectSceneOptions options;
  options.num_images = 11;
  options.num_points = 300;
  options.seed = seed;
  Reconstruction r = datasets::MakeObjectScene(options).reconstruction;
  const Camera base = r.cameras.begin()->second;
  const std::vector<std::vector<double>> extra = {
      {},
      {},
      {0.01},
      {0.01, -0.002},
      {0.01, -0.002, 0.001, 0.0005},
      {0.01, -0.002, 0.001, 0.0005},
      {0.01, -0.002, 0.001, 0.0005, 0.0001, 0.0002, -0.0001, 0.00005},
      {0.3},
      {0.01},
      {0.01, -0.002},
      {0.01, -0.002, 0.001, 0.0005, 0.0001, 0.0002, -0.0001, 0.00005}};
  r.cameras.clear();
  for (int model = 0; model < kNumCameraModels; ++model) {
    Camera c = base;
    c.camera_id = CameraId(static_cast<std::uint32_t>(model + 1));
    c.model = CameraModelId(model);
    const bool single = model == 0 || model == 2 || model == 3 || model == 8 || model == 9;
    c.params = single ? std::vector<double>{600.0 + model, 320.0, 240.0}
                      : std::vector<double>{600.0 + model, 601.5, 320.25, 239.75};
    for (double e : extra[static_cast<std::size_t>(model)]) c.params.push_back(e);
    r.cameras[c.camera_id] = c;
  }
  std::uint32_t k = 0;
  for (auto& [id, image] : r.images) {
    image.camera_id = CameraId(1 + (k++ % kNumCameraModels));
  }
  return r;
}

}  // namespace texlume::sfm

#include "mesh/ray_caster.h"

#include <embree3/rtcore.h>

#include <limits>
#include <stdexcept>
#include <string>

namespace texlume::mesh {

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayCaster::RayCaster(const std::vector<Eigen::Vector3f>& positions,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles, bool high_quality)
    : impl_(new Impl) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  RTCGeometry mesh = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
  for (std::size_t i = 0; i < positions.size(); ++i)
    for (int c = 0; c < 3; ++c) vertices[3 * i + static_cast<std::size_t>(c)] = positions[i][c];
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) indices[3 * i + c] = triangles[i][c];
  rtcCommitGeometry(mesh);
  rtcAttachGeometry(impl_->scene, mesh);
  rtcReleaseGeometry(mesh);
  if (high_quality) rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  rtcCommitScene(impl_->scene);
  const RTCError error = rtcGetDeviceError(impl_->device);
  if (error != RTC_ERROR_NONE) {
    throw std::runtime_error("Embree: scene build failed (error " + std::to_string(error) + ")");
  }
}

RayCaster::~RayCaster() = default;

std::optional<RayCaster::Hit> RayCaster::Intersect(const Eigen::Vector3d& origin,
                                                   const Eigen::Vector3d& direction) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(direction.x());
  rh.ray.dir_y = static_cast<float>(direction.y());
  rh.ray.dir_z = static_cast<float>(direction.z());
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.time = 0.0f;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return Hit{rh.hit.primID, rh.hit.u, rh.hit.v, rh.ray.tfar,
             Eigen::Vector3d(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)};
}

bool RayCaster::Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         float near) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x());
  ray.org_y = static_cast<float>(origin.y());
  ray.org_z = static_cast<float>(origin.z());
  ray.dir_x = static_cast<float>(direction.x());
  ray.dir_y = static_cast<float>(direction.y());
  ray.dir_z = static_cast<float>(direction.z());
  ray.tnear = near;
  ray.tfar = std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFu;
  ray.time = 0.0f;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.0f;
}

std::unique_ptr<RayCaster> RayCasterOf(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices) positions.push_back(v.cast<float>());
  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(mesh.faces.size());
  for (const auto& f : mesh.faces)
    triangles.push_back({static_cast<std::uint32_t>(f[0]), static_cast<std::uint32_t>(f[1]),
                         static_cast<std::uint32_t>(f[2])});
  return std::make_unique<RayCaster>(positions, triangles);
}

}  // namespace texlume::mesh

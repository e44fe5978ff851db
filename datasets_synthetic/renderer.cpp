#include "datasets_synthetic/renderer.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "mesh/ray_caster.h"

namespace texlume::datasets {
namespace {

constexpr double kTwoPi = 6.283185307179586;

void AddVertex(DisplacedGeometry& g, const SurfacePatch& patch, const BakedMaterial& material,
               double u, double v) {
  const SurfacePoint s = patch.eval(u, v);
  const double h = material.Height(u, v);
  g.positions.push_back((s.position + h * s.normal).cast<float>());
  g.uv.emplace_back(static_cast<float>(u), static_cast<float>(v));
  g.normal.push_back(s.normal.cast<float>());
  g.d_du.push_back(s.d_du.cast<float>());
  g.d_dv.push_back(s.d_dv.cast<float>());
}

void AddQuad(DisplacedGeometry& g, std::uint32_t a, std::uint32_t b, std::uint32_t c,
             std::uint32_t d, std::uint16_t patch) {
  // a-b along u, a-d along v: (a, b, c) and (a, c, d) keep d_du x d_dv outwards.
  g.triangles.push_back({a, b, c});
  g.triangles.push_back({a, c, d});
  g.triangle_patch.push_back(patch);
  g.triangle_patch.push_back(patch);
}

double Srgb(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double SrgbToLinear(double s) {
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

}  // namespace

DisplacedGeometry DisplacePatches(const std::vector<SurfacePatch>& patches,
                                  const std::vector<const BakedMaterial*>& materials, double step) {
  if (patches.size() != materials.size()) {
    throw std::invalid_argument("DisplacePatches: one material per patch");
  }
  if (!(step > 0.0)) throw OptionError("tessellation step must be positive");
  DisplacedGeometry g;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const SurfacePatch& patch = patches[p];
    const BakedMaterial& material = *materials[p];
    const auto patch_id = static_cast<std::uint16_t>(p);
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    if (patch.domain == SurfacePatch::Domain::kRectangle) {
      const int nu = std::max(1, static_cast<int>(std::ceil((patch.u1 - patch.u0) / step)));
      const int nv = std::max(1, static_cast<int>(std::ceil((patch.v1 - patch.v0) / step)));
      // The seam column of a periodic patch is duplicated (same position, u = u1)
      // so that material coordinates interpolate without a jump.
      for (int j = 0; j <= nv; ++j) {
        for (int i = 0; i <= nu; ++i) {
          AddVertex(g, patch, material, patch.u0 + (patch.u1 - patch.u0) * i / nu,
                    patch.v0 + (patch.v1 - patch.v0) * j / nv);
        }
      }
      auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (nu + 1) + i); };
      for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i)
          AddQuad(g, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1), patch_id);
      }
    } else {
      // Disk inscribed in the rectangle: polar grid, rings of equal segment count.
      const double cu = (patch.u0 + patch.u1) / 2, cv = (patch.v0 + patch.v1) / 2;
      const double radius = (patch.u1 - patch.u0) / 2;
      const int rings = std::max(1, static_cast<int>(std::ceil(radius / step)));
      const int segments = std::max(8, static_cast<int>(std::ceil(kTwoPi * radius / step)));
      AddVertex(g, patch, material, cu, cv);
      for (int k = 1; k <= rings; ++k) {
        const double rho = radius * k / rings;
        for (int j = 0; j < segments; ++j) {
          const double t = kTwoPi * j / segments;
          AddVertex(g, patch, material, cu + rho * std::cos(t), cv + rho * std::sin(t));
        }
      }
      auto at = [&](int k, int j) {
        return base +
               (k == 0 ? 0u : static_cast<std::uint32_t>(1 + (k - 1) * segments + (j % segments)));
      };
      for (int j = 0; j < segments; ++j) {
        g.triangles.push_back({at(0, 0), at(1, j), at(1, j + 1)});
        g.triangle_patch.push_back(patch_id);
      }
      for (int k = 1; k < rings; ++k) {
        for (int j = 0; j < segments; ++j) {
          // Radial is like u and angular like v here: keep the winding outwards.
          g.triangles.push_back({at(k, j), at(k + 1, j), at(k + 1, j + 1)});
          g.triangles.push_back({at(k, j), at(k + 1, j + 1), at(k, j + 1)});
          g.triangle_patch.push_back(patch_id);
          g.triangle_patch.push_back(patch_id);
        }
      }
    }
  }
  return g;
}

struct Renderer::Impl {
  std::unique_ptr<mesh::RayCaster> caster;
};

Renderer::Renderer(DisplacedGeometry geometry, std::vector<const BakedMaterial*> materials)
    : geometry_(std::move(geometry)), materials_(std::move(materials)), impl_(new Impl) {
  for (std::uint16_t p : geometry_.triangle_patch) {
    if (p >= materials_.size()) throw std::invalid_argument("Renderer: missing material");
  }
  impl_->caster = std::make_unique<mesh::RayCaster>(geometry_.positions, geometry_.triangles,
                                                    /*high_quality=*/true);
}

Renderer::~Renderer() = default;

void ShadingOptions::Check() const {
  if (!(ambient >= 0.0 && ambient <= 1.0)) throw OptionError("ambient must be in [0, 1]");
  if (!(exposure > 0.0) || !std::isfinite(exposure)) throw OptionError("exposure must be > 0");
  if (samples_per_axis < 1 || samples_per_axis > 8)
    throw OptionError("samples_per_axis must be in [1, 8]");
}

template <typename RayAt>
Rendering Renderer::Render(int width, int height, const RayAt& ray_at,
                           const std::vector<RenderLight>& lights,
                           const ShadingOptions& options) const {
  options.Check();
  Rendering out;
  out.linear_rgb = cv::Mat(height, width, CV_32FC3, cv::Scalar::all(0));
  out.coverage = cv::Mat(height, width, CV_32FC1, cv::Scalar::all(0));
  const int n = options.samples_per_axis;
  const double inv_samples = 1.0 / (n * n);
  std::vector<Eigen::Vector3d> light_dirs;
  for (const auto& l : lights) light_dirs.push_back(l.direction_in_world.normalized());

#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int hits = 0;
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          Eigen::Vector3d origin, direction;
          if (!ray_at(x + (sx + 0.5) / n, y + (sy + 0.5) / n, origin, direction)) continue;
          const std::optional<mesh::RayCaster::Hit> hit =
              impl_->caster->Intersect(origin, direction);
          if (!hit) continue;
          ++hits;
          const auto& tri = geometry_.triangles[hit->triangle];
          const double b1 = hit->b1, b2 = hit->b2, b0 = 1.0 - b1 - b2;
          auto interp3 = [&](const std::vector<Eigen::Vector3f>& a) {
            return (b0 * a[tri[0]].cast<double>() + b1 * a[tri[1]].cast<double>() +
                    b2 * a[tri[2]].cast<double>())
                .eval();
          };
          const Eigen::Vector2d uv = b0 * geometry_.uv[tri[0]].cast<double>() +
                                     b1 * geometry_.uv[tri[1]].cast<double>() +
                                     b2 * geometry_.uv[tri[2]].cast<double>();
          const Eigen::Vector3d base_normal = interp3(geometry_.normal).normalized();
          const BakedMaterial& material = *materials_[geometry_.triangle_patch[hit->triangle]];
          // Shading normal of the displaced surface: (S_u + h_u N) x (S_v + h_v N).
          const Eigen::Vector2d grad = material.HeightGradient(uv.x(), uv.y());
          const Eigen::Vector3d tu = interp3(geometry_.d_du) + grad.x() * base_normal;
          const Eigen::Vector3d tv = interp3(geometry_.d_dv) + grad.y() * base_normal;
          Eigen::Vector3d normal = tu.cross(tv);
          normal = normal.norm() > 1e-9 ? Eigen::Vector3d(normal.normalized()) : base_normal;
          Eigen::Vector3d geometric_normal = hit->geometric_normal;
          geometric_normal.normalize();
          if (geometric_normal.dot(direction) > 0) geometric_normal = -geometric_normal;
          const Eigen::Vector3d albedo = material.Albedo(uv.x(), uv.y());
          const Eigen::Vector3d position = origin + static_cast<double>(hit->distance) * direction;
          const Eigen::Vector3d to_viewer = -direction;
          Eigen::Vector3d radiance = options.ambient * albedo;
          for (std::size_t li = 0; li < lights.size(); ++li) {
            const Eigen::Vector3d& l = light_dirs[li];
            const double n_dot_l = normal.dot(l);
            if (n_dot_l <= 0.0) continue;
            if (options.shadows) {
              const Eigen::Vector3d start = position + 1e-5 * geometric_normal;
              if (impl_->caster->Occluded(start, l, 1e-5f)) continue;
            }
            double specular = 0.0;
            if (material.options().specular > 0.0) {
              const Eigen::Vector3d half = (l + to_viewer).normalized();
              specular = material.options().specular *
                         std::pow(std::max(0.0, normal.dot(half)), material.options().shininess);
            }
            radiance +=
                lights[li].intensity * (albedo * n_dot_l + Eigen::Vector3d::Constant(specular));
          }
          sum += radiance;
        }
      }
      const Eigen::Vector3d value = sum * (inv_samples * options.exposure);
      auto* pixel = out.linear_rgb.ptr<cv::Vec3f>(y) + x;
      (*pixel)[0] = static_cast<float>(value.x());
      (*pixel)[1] = static_cast<float>(value.y());
      (*pixel)[2] = static_cast<float>(value.z());
      out.coverage.at<float>(y, x) = static_cast<float>(hits * inv_samples);
    }
  }
  return out;
}

Rendering Renderer::RenderPerspective(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                                      const std::vector<RenderLight>& lights,
                                      const ShadingOptions& options) const {
  const sfm::Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Matrix3d rotation = world_from_cam.rotation.toRotationMatrix();
  const Eigen::Vector3d center = world_from_cam.translation;
  return Render(
      static_cast<int>(camera.width), static_cast<int>(camera.height),
      [&](double px, double py, Eigen::Vector3d& origin, Eigen::Vector3d& direction) {
        const Eigen::Vector3d ray = camera.CamRayFromImage({px, py});
        if (!(ray.z() > 0.0)) return false;
        origin = center;
        direction = rotation * ray;
        return true;
      },
      lights, options);
}

Rendering Renderer::RenderOrthographic(int width, int height, double u0, double v_top,
                                       double texel_size, const Eigen::Vector3d& view_direction,
                                       const std::vector<RenderLight>& lights,
                                       const ShadingOptions& options) const {
  const Eigen::Vector3d w = view_direction.normalized();
  if (!(w.z() > 0.05)) throw OptionError("orthographic view must come from above the sample");
  return Render(
      width, height,
      [&](double px, double py, Eigen::Vector3d& origin, Eigen::Vector3d& direction) {
        const Eigen::Vector3d on_plane(u0 + px * texel_size, v_top - py * texel_size, 0.0);
        origin = on_plane + w * (10.0 / w.z());  // ten world units above the plane
        direction = -w;
        return true;
      },
      lights, options);
}

cv::Mat LinearToSrgb8(const cv::Mat& linear_rgb) {
  CV_Assert(linear_rgb.type() == CV_32FC3);
  cv::Mat out(linear_rgb.rows, linear_rgb.cols, CV_8UC3);
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const auto* in = linear_rgb.ptr<cv::Vec3f>(y);
    auto* o = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < linear_rgb.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        o[x][2 - c] = static_cast<std::uint8_t>(std::lround(255.0 * Srgb(in[x][c])));
      }
    }
  }
  return out;
}

cv::Mat Srgb8ToLinear(const cv::Mat& srgb_bgr) {
  CV_Assert(srgb_bgr.type() == CV_8UC3);
  float table[256];
  for (int i = 0; i < 256; ++i) table[i] = static_cast<float>(SrgbToLinear(i / 255.0));
  cv::Mat out(srgb_bgr.rows, srgb_bgr.cols, CV_32FC3);
  for (int y = 0; y < srgb_bgr.rows; ++y) {
    const auto* in = srgb_bgr.ptr<cv::Vec3b>(y);
    auto* o = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < srgb_bgr.cols; ++x) {
      for (int c = 0; c < 3; ++c) o[x][c] = table[in[x][2 - c]];
    }
  }
  return out;
}

}  // namespace texlume::datasets

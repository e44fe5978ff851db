#include "datasets_synthetic/renderer.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>
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

namespace {

// splitmix64: a fixed, well-mixed sequence per pixel sample, so one bounce of
// interreflection is deterministic whatever the thread count.
struct SampleSequence {
  std::uint64_t state;
  double Next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }
};

// Where a ray met the displaced surface, with what shading needs there.
struct SurfaceHit {
  Eigen::Vector3d position, normal, geometric_normal, albedo;
  const MaterialOptions* material = nullptr;
};

// Shades rays against the displaced geometry: Lambert, Blinn-Phong and sheen per
// light with shadow rays, an ambient term, and optionally one bounce of diffuse
// interreflection (docs/synthetic_scenes.md, Rendering).
class SurfaceShader {
 public:
  SurfaceShader(const DisplacedGeometry& geometry,
                const std::vector<const BakedMaterial*>& materials, const mesh::RayCaster& caster,
                const std::vector<RenderLight>& lights, const ShadingOptions& options)
      : geometry_(geometry), materials_(materials), caster_(caster), options_(options) {
    for (const auto& l : lights)
      lights_.push_back({l.direction_in_world.normalized(), l.intensity});
  }

  // The radiance along a camera ray, or nothing when it misses.
  std::optional<Eigen::Vector3d> Radiance(const Eigen::Vector3d& origin,
                                          const Eigen::Vector3d& direction,
                                          SampleSequence& sequence) const {
    const std::optional<SurfaceHit> p = Trace(origin, direction);
    if (!p) return std::nullopt;
    Eigen::Vector3d radiance = options_.ambient * p->albedo;
    AddDirect(*p, -direction, true, radiance);
    if (options_.interreflection_rays > 0) radiance += Indirect(*p, sequence);
    return radiance;
  }

 private:
  std::optional<SurfaceHit> Trace(const Eigen::Vector3d& origin,
                                  const Eigen::Vector3d& direction) const {
    const std::optional<mesh::RayCaster::Hit> hit = caster_.Intersect(origin, direction);
    if (!hit) return std::nullopt;
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
    SurfaceHit p;
    // Shading normal of the displaced surface: (S_u + h_u N) x (S_v + h_v N).
    const Eigen::Vector2d grad = material.HeightGradient(uv.x(), uv.y());
    const Eigen::Vector3d tu = interp3(geometry_.d_du) + grad.x() * base_normal;
    const Eigen::Vector3d tv = interp3(geometry_.d_dv) + grad.y() * base_normal;
    p.normal = tu.cross(tv);
    p.normal = p.normal.norm() > 1e-9 ? Eigen::Vector3d(p.normal.normalized()) : base_normal;
    p.geometric_normal = hit->geometric_normal.normalized();
    if (p.geometric_normal.dot(direction) > 0) p.geometric_normal = -p.geometric_normal;
    p.albedo = material.Albedo(uv.x(), uv.y());
    p.position = origin + hit->distance * direction;
    p.material = &material.options();
    return p;
  }

  bool Lit(const SurfaceHit& p, const Eigen::Vector3d& l) const {
    if (!options_.shadows) return true;
    return !caster_.Occluded(p.position + 1e-5 * p.geometric_normal, l, 1e-5f);
  }

  // Adds the light arriving straight from the lights and leaving towards the
  // viewer; `glossy` adds the specular lobe and the sheen to the Lambertian term.
  void AddDirect(const SurfaceHit& p, const Eigen::Vector3d& to_viewer, bool glossy,
                 Eigen::Vector3d& radiance) const {
    const MaterialOptions& m = *p.material;
    for (const auto& [l, intensity] : lights_) {
      const double n_dot_l = p.normal.dot(l);
      if (n_dot_l <= 0.0 || !Lit(p, l)) continue;
      double white = 0.0;
      if (glossy && (m.specular > 0.0 || m.sheen > 0.0)) {
        const Eigen::Vector3d half = (l + to_viewer).normalized();
        white = m.specular * std::pow(std::max(0.0, p.normal.dot(half)), m.shininess) +
                m.sheen * std::pow(1.0 - std::clamp(l.dot(half), 0.0, 1.0), 5.0) * n_dot_l;
      }
      radiance += intensity * (p.albedo * n_dot_l + Eigen::Vector3d::Constant(white));
    }
  }

  // One bounce of diffuse interreflection: the albedo times the mean Lambertian
  // radiance of the surface seen along cosine-distributed rays (a Monte Carlo
  // estimate of the irradiance / pi, in the units of Direct).
  Eigen::Vector3d Indirect(const SurfaceHit& p, SampleSequence& sequence) const {
    const Eigen::Vector3d& n = p.normal;
    const Eigen::Vector3d t =
        (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY())
            .cross(n)
            .normalized();
    const Eigen::Vector3d b = n.cross(t);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = 0; k < options_.interreflection_rays; ++k) {
      const double u1 = sequence.Next(), phi = kTwoPi * sequence.Next();
      const double r = std::sqrt(u1);
      const Eigen::Vector3d d =
          r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1 - u1) * n;
      if (d.dot(p.geometric_normal) <= 0.0) continue;
      const std::optional<SurfaceHit> q = Trace(p.position + 1e-5 * p.geometric_normal, d);
      if (q) AddDirect(*q, -d, false, sum);
    }
    return p.albedo.cwiseProduct(sum) / options_.interreflection_rays;
  }

  const DisplacedGeometry& geometry_;
  const std::vector<const BakedMaterial*>& materials_;
  const mesh::RayCaster& caster_;
  const ShadingOptions& options_;
  std::vector<std::pair<Eigen::Vector3d, double>> lights_;  // direction, intensity
};

}  // namespace

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
  if (interreflection_rays < 0 || interreflection_rays > 64)
    throw OptionError("interreflection_rays must be in [0, 64]");
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
  const SurfaceShader shader(geometry_, materials_, *impl_->caster, lights, options);

#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int hits = 0;
      SampleSequence sequence{(static_cast<std::uint64_t>(y) * width + x) * 0x100000001B3ull};
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          Eigen::Vector3d origin, direction;
          if (!ray_at(x + (sx + 0.5) / n, y + (sy + 0.5) / n, origin, direction)) continue;
          const std::optional<Eigen::Vector3d> radiance =
              shader.Radiance(origin, direction, sequence);
          if (!radiance) continue;
          ++hits;
          sum += *radiance;
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

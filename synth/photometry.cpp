#include "synth/photometry.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "synth/triangle_parts.h"

namespace texlume::synth {
namespace {

constexpr int kKnots = ptm::LightResponse::kKnots;
constexpr int kAmbient = kKnots, kOrenNayar = kKnots + 1;
constexpr int kUnknowns = kKnots + 2;  // the knots, the ambient, Oren and Nayar's B / A
using Row = Eigen::Matrix<double, 1, kUnknowns>;
using Vector = Eigen::Matrix<double, kUnknowns, 1>;
using Matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>;
// The knots and the ambient alone: a view-blind response is solved and predicted in
// these, in the same sums as before the view term (the same bits).
constexpr int kViewBlind = kKnots + 1;
using ViewBlindRow = Eigen::Matrix<double, 1, kViewBlind>;

constexpr double kUnlitFloor = 0.03;  // linear R + G + B per cell: errors relative to at least this
constexpr double kHuberScale = 1.5;   // in robust standard deviations of the relative residual
// A photo's white balance past these is not a camera's setting but faces no
// other photo saw.
constexpr std::pair<double, double> kWhiteBalanceRange{0.5, 2.0};

// Adds `value` at `elevation_deg` to a row's knot columns, linear between knots.
void AddToKnots(double elevation_deg, double value, Row& row) {
  const ptm::KnotWeights w = ptm::KnotWeightsAt(elevation_deg);
  row[w.lower] += (1.0 - w.upper_weight) * value;
  row[w.lower + 1] += w.upper_weight * value;
}

// The observation's prediction as a row: linear in the knots and the ambient at
// the Oren-Nayar ratio b (its own column 0).
Row DesignRow(const PhotometricObservation& o, double b) {
  Row row = Row::Zero();
  for (const PhotometricObservation::Light& l : o.lights)
    AddToKnots(l.elevation_deg, l.relit * (1.0 + b * l.oren_nayar), row);
  row[kAmbient] = o.zenith_linear;
  return row;
}

// DesignRow at the current response r0 with the Oren-Nayar ratio's column as well,
// linearised about r0 (Gauss-Newton): d prediction / d b = sum_l r0(theta_l) P_l s_l.
// The target then gains b0 times that column.
Row LinearisedRow(const PhotometricObservation& o, const ptm::LightResponse& r0) {
  Row slope = Row::Zero();  // sum_l P_l s_l spread over the knots
  for (const PhotometricObservation::Light& l : o.lights)
    AddToKnots(l.elevation_deg, l.relit * l.oren_nayar, slope);
  Row row = DesignRow(o, r0.oren_nayar_b_over_a);
  for (int k = 0; k < kKnots; ++k)
    row[kOrenNayar] += slope[k] * r0.elevation_factor[static_cast<std::size_t>(k)];
  return row;
}

// A row's prediction under the unknowns x: the knots' and the ambient's part (the
// Oren-Nayar ratio is in the knots' columns already; its own column is 0 but in
// LinearisedRow).
double PredictionOf(const Row& row, const Vector& x) {
  return ViewBlindRow(row.head<kViewBlind>()).dot(ViewBlindRow(x.head<kViewBlind>().transpose()));
}

Vector ToVector(const ptm::LightResponse& r) {
  Vector x;
  for (int k = 0; k < kKnots; ++k) x[k] = r.elevation_factor[static_cast<std::size_t>(k)];
  x[kAmbient] = r.ambient;
  x[kOrenNayar] = r.oren_nayar_b_over_a;
  return x;
}

// Gains and albedos from the steep observations under the current response;
// the gains' mean log then set to 0.
std::vector<double> GainsUnder(const std::vector<PhotometricObservation>& observations,
                               std::size_t num_faces, std::size_t num_photos,
                               const ptm::LightResponse& response, std::vector<double>& albedo,
                               bool anchor_to_lights, std::vector<bool>* photo_observed = nullptr) {
  std::vector<GainObservation> ratios;
  for (const PhotometricObservation& o : observations) {
    const double model = o.Predicted(response);
    // Dim faces (grazing light, shadow) say little about the gain.
    if (!o.steep || !(model > 0.02 * 3 * o.cells) || !(o.photo_linear > 1e-6)) continue;
    ratios.push_back({o.face, o.photo, std::log(o.photo_linear / model), model});
  }
  std::vector<double> gains = SolvePhotoGains(ratios, num_faces, num_photos, &albedo);
  if (!anchor_to_lights) return gains;
  // Once more with Huber weights: a cast shadow or a highlight on one face in
  // one photo must not move that face's albedo, nor through it the response.
  std::vector<double> residual;
  for (const GainObservation& r : ratios)
    residual.push_back(std::abs(r.log_m - std::log(gains[r.photo] * albedo[r.face])));
  std::vector<double> sorted = residual;
  if (!sorted.empty()) {
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double sigma = std::max(1e-3, 1.4826 * sorted[sorted.size() / 2]);
    for (std::size_t i = 0; i < ratios.size(); ++i)
      ratios[i].weight *= std::min(1.0, kHuberScale * sigma / std::max(1e-12, residual[i]));
    gains = SolvePhotoGains(ratios, num_faces, num_photos, &albedo);
  }
  std::vector<bool> observed(num_photos, false);
  for (const GainObservation& r : ratios) observed[r.photo] = true;
  if (photo_observed) *photo_observed = observed;
  double mean_log = 0.0;
  int count = 0;
  for (std::size_t n = 0; n < num_photos; ++n)
    if (observed[n]) mean_log += std::log(gains[n]), ++count;
  if (count == 0) return gains;
  const double scale = std::exp(mean_log / count);
  for (double& g : gains) g /= scale;
  return gains;
}

// One weighted least-squares solve of the response (see SolvePhotometry).
class ResponseFit {
 public:
  void Add(const Row& row, double target, double weight) {
    normal_ += weight * row.transpose() * row;
    rhs_ += weight * target * row.transpose();
    // The best single factor on every light (no ambient): where knots go
    // without observations.
    const double lit = row.head<kKnots>().sum();
    single_num_ += weight * target * lit;
    single_den_ += weight * lit * lit;
  }

  // With `view_term`, the Oren-Nayar ratio too, damped towards `b0` (the
  // linearisation's point); without, it stays 0.
  ptm::LightResponse Solve(bool view_term, double b0) const {
    const double single = single_den_ > 0 ? single_num_ / single_den_ : 1.0;
    Vector x = Vector::Zero();
    if (view_term)
      x = Regularised<kUnknowns>(normal_, rhs_, single, b0);
    else
      x.head<kViewBlind>() = Regularised<kViewBlind>(
          normal_.topLeftCorner<kViewBlind, kViewBlind>(), rhs_.head<kViewBlind>(), single, 0.0);
    ptm::LightResponse r;
    for (int k = 0; k < kKnots; ++k)
      r.elevation_factor[static_cast<std::size_t>(k)] = std::clamp(x[k], 0.25, 4.0);
    r.ambient = std::clamp(x[kAmbient], 0.0, 0.5);
    r.oren_nayar_b_over_a = std::clamp(x[kOrenNayar], 0.0, 2.0);
    return r;
  }

 private:
  // The normal equations of the first N unknowns with the second differences of
  // the knots penalised, knots drawn to `single`, the Oren-Nayar ratio (N > its
  // index) to `b0`; the ambient and the ratio fixed at 0 where they come out negative.
  template <int N>
  static Eigen::Matrix<double, N, 1> Regularised(Eigen::Matrix<double, N, N> a,
                                                 Eigen::Matrix<double, N, 1> b, double single,
                                                 double b0) {
    const double scale = std::max(1e-12, a.diagonal().template head<kKnots>().sum() / kKnots);
    const double smooth = 0.05 * scale, ridge = 1e-3 * scale;
    for (int k = 1; k + 1 < kKnots; ++k) {  // (r_k-1 - 2 r_k + r_k+1)^2
      Eigen::Matrix<double, 1, N> d = Eigen::Matrix<double, 1, N>::Zero();
      d[k - 1] = 1, d[k] = -2, d[k + 1] = 1;
      a += smooth * d.transpose() * d;
    }
    for (int k = 0; k < kKnots; ++k) a(k, k) += ridge, b[k] += ridge * single;
    a(kAmbient, kAmbient) += ridge;
    if constexpr (N > kOrenNayar) a(kOrenNayar, kOrenNayar) += ridge, b[kOrenNayar] += ridge * b0;
    Eigen::Matrix<double, N, 1> x = a.ldlt().solve(b);
    for (int unknown = kAmbient; unknown < N; ++unknown)  // none may be negative
      if (!(x[unknown] >= 0.0)) {
        a.row(unknown).setZero(), a.col(unknown).setZero(), a(unknown, unknown) = 1, b[unknown] = 0;
        x = a.ldlt().solve(b);
      }
    return x;
  }

  Matrix normal_ = Matrix::Zero();
  Vector rhs_ = Vector::Zero();
  double single_num_ = 0.0, single_den_ = 0.0;
};

// Each observation's weight in the response's least squares, at the current
// response: relative errors (a floor for the unlit) and Huber weights; 0 for an
// observation without a known albedo or gain.
std::vector<double> ResponseWeights(const std::vector<PhotometricObservation>& observations,
                                    const std::vector<double>& gains,
                                    const std::vector<double>& albedo,
                                    const std::vector<bool>& photo_observed,
                                    const ptm::LightResponse& current) {
  const Vector x = ToVector(current);
  std::vector<double> relative(observations.size(), 0.0), scale(observations.size(), 0.0);
  std::vector<double> magnitudes;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const PhotometricObservation& o = observations[i];
    // Faces without a steep view and photos without one have no albedo or gain.
    if (!(albedo[o.face] > 0.0 && photo_observed[o.photo])) continue;
    const double target = o.photo_linear / (gains[o.photo] * albedo[o.face]);
    const double model = PredictionOf(DesignRow(o, current.oren_nayar_b_over_a), x);
    scale[i] = std::max(model, kUnlitFloor * std::max(1, o.cells));
    relative[i] = (target - model) / scale[i];
    magnitudes.push_back(std::abs(relative[i]));
  }
  std::vector<double> weight(observations.size(), 0.0);
  if (magnitudes.empty()) return weight;
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                   magnitudes.end());
  const double sigma = std::max(1e-3, 1.4826 * magnitudes[magnitudes.size() / 2]);
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (!(scale[i] > 0.0)) continue;
    const double huber =
        std::min(1.0, kHuberScale * sigma / std::max(1e-12, std::abs(relative[i])));
    weight[i] = std::min(observations[i].cells, 64) * huber / (scale[i] * scale[i]);
  }
  return weight;
}

ptm::LightResponse ResponseUnder(const std::vector<PhotometricObservation>& observations,
                                 const std::vector<double>& gains,
                                 const std::vector<double>& albedo,
                                 const std::vector<bool>& photo_observed,
                                 const ptm::LightResponse& current, bool estimate_view_term) {
  const std::vector<double> weight =
      ResponseWeights(observations, gains, albedo, photo_observed, current);
  if (std::none_of(weight.begin(), weight.end(), [](double w) { return w > 0.0; })) return current;
  ResponseFit fit;
  const double b0 = current.oren_nayar_b_over_a;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (!(weight[i] > 0.0)) continue;
    const PhotometricObservation& o = observations[i];
    const Row row = LinearisedRow(o, current);
    fit.Add(row, o.photo_linear / (gains[o.photo] * albedo[o.face]) + b0 * row[kOrenNayar],
            weight[i]);
  }
  return fit.Solve(estimate_view_term, b0);
}

}  // namespace

std::vector<std::array<double, 3>> SolveWhiteBalance(
    const std::vector<PhotometricObservation>& observations, std::size_t num_faces,
    std::size_t num_photos) {
  std::vector<std::array<double, 3>> log_w(num_photos, {0.0, 0.0, 0.0});
  std::vector<int> observed_channels(num_photos, 0);  // bit c: channel c observed
  for (int c = 0; c < 3; ++c) {
    std::vector<GainObservation> ratios;
    for (const PhotometricObservation& o : observations) {
      const double sum = o.photo_channels[0] + o.photo_channels[1] + o.photo_channels[2];
      const double channel = o.photo_channels[static_cast<std::size_t>(c)];
      if (!o.steep || !(channel > 1e-6) || !(sum > 0.02 * 3 * o.cells)) continue;
      ratios.push_back({o.face, o.photo, std::log(channel / sum), sum});
      observed_channels[o.photo] |= 1 << c;
    }
    const std::vector<double> w = SolvePhotoGains(ratios, num_faces, num_photos);
    for (std::size_t n = 0; n < num_photos; ++n)
      log_w[n][static_cast<std::size_t>(c)] = std::log(w[n]);
  }
  std::vector<bool> observed(num_photos, false);  // only photos seen in all three
  for (std::size_t n = 0; n < num_photos; ++n) observed[n] = observed_channels[n] == 7;
  for (auto& row : log_w) {  // centred over each photo's channels
    const double mean = (row[0] + row[1] + row[2]) / 3.0;
    for (double& v : row) v -= mean;
  }
  std::size_t count = 0;
  std::array<double, 3> mean{0.0, 0.0, 0.0};
  for (std::size_t n = 0; n < num_photos; ++n)
    if (observed[n]) {
      ++count;
      for (std::size_t c = 0; c < 3; ++c) mean[c] += log_w[n][c];
    }
  std::vector<std::array<double, 3>> w(num_photos, {1.0, 1.0, 1.0});
  for (std::size_t n = 0; n < num_photos; ++n)
    if (observed[n])
      for (std::size_t c = 0; c < 3; ++c)
        w[n][c] = std::clamp(std::exp(log_w[n][c] - mean[c] / static_cast<double>(count)),
                             kWhiteBalanceRange.first, kWhiteBalanceRange.second);
  return w;
}

double PhotometricObservation::Predicted(const ptm::LightResponse& response) const {
  return PredictionOf(DesignRow(*this, response.oren_nayar_b_over_a), ToVector(response));
}

Photometry SolvePhotometry(std::vector<PhotometricObservation> observations, std::size_t num_faces,
                           std::size_t num_photos, bool estimate_response,
                           bool estimate_white_balance, bool estimate_view_term) {
  Photometry p;
  p.white_balance.assign(num_photos, {1.0, 1.0, 1.0});
  if (estimate_white_balance) {
    p.white_balance = SolveWhiteBalance(observations, num_faces, num_photos);
    for (PhotometricObservation& o : observations) {
      o.photo_linear = 0.0;
      for (std::size_t c = 0; c < 3; ++c)
        o.photo_linear += o.photo_channels[c] / p.white_balance[o.photo][c];
    }
  }
  std::vector<double> albedo;
  p.photo_gains = GainsUnder(observations, num_faces, num_photos, p.response, albedo, false);
  if (!estimate_response) return p;
  std::vector<bool> photo_observed;
  for (int round = 0; round < 6; ++round) {
    p.photo_gains =
        GainsUnder(observations, num_faces, num_photos, p.response, albedo, true, &photo_observed);
    p.response = ResponseUnder(observations, p.photo_gains, albedo, photo_observed, p.response,
                               estimate_view_term);
  }
  p.photo_gains = GainsUnder(observations, num_faces, num_photos, p.response, albedo, true);
  return p;
}

std::vector<char> PhotometryFaces(const std::vector<std::vector<std::uint32_t>>& photos_of_face,
                                  std::size_t num_photos, std::size_t limit,
                                  std::size_t min_per_photo) {
  const std::size_t num_faces = photos_of_face.size();
  std::vector<char> observed(num_faces, 1);
  if (num_faces <= limit) return observed;
  const std::size_t stride = (num_faces + limit - 1) / limit;
  std::vector<std::size_t> seen(num_photos, 0), kept(num_photos, 0);
  for (std::size_t f = 0; f < num_faces; ++f) {
    observed[f] = f % stride == 0 ? 1 : 0;
    for (const std::uint32_t p : photos_of_face[f]) ++seen[p], kept[p] += observed[f];
  }
  // A photo left with too few: every step-th of its faces as well.
  std::vector<std::size_t> step(num_photos, 0), index(num_photos, 0);
  for (std::size_t p = 0; p < num_photos; ++p)
    if (kept[p] < min_per_photo) step[p] = std::max<std::size_t>(1, seen[p] / min_per_photo);
  for (std::size_t f = 0; f < num_faces; ++f)
    for (const std::uint32_t p : photos_of_face[f])
      if (step[p] > 0 && index[p]++ % step[p] == 0) observed[f] = 1;
  return observed;
}

}  // namespace texlume::synth

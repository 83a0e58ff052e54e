#include "nphand/eval/regression.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Cholesky>

#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

bool Fail(std::string* why, const std::string& text) {
  *why = text;
  return false;
}

void CheckTraining(const std::string& name, const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, Eigen::Index least) {
  NPHAND_THROW_CHECK(x.rows() == y.rows(), name, ": ", x.rows(), " descriptors but ", y.rows(), " poses");
  NPHAND_THROW_CHECK(x.rows() >= least, name, ": needs at least ", least, " training rows, not ", x.rows());
  NPHAND_THROW_CHECK(x.cols() > 0 && y.cols() > 0, name, ": empty descriptors or poses");
  NPHAND_THROW_CHECK(x.allFinite() && y.allFinite(), name, ": a training value is not a finite number");
}

void CheckQuery(const std::string& name, Eigen::Index fitted_width, const Eigen::MatrixXd& x) {
  NPHAND_THROW_CHECK(fitted_width > 0, name, ": predict before fit");
  NPHAND_THROW_CHECK(x.cols() == fitted_width, name, ": descriptors of ", x.cols(), " values, fitted on ",
                     fitted_width);
}

// Squared distances between the rows of a and the rows of b (a.rows() x b.rows()).
Eigen::MatrixXd SquaredDistances(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::VectorXd na = a.rowwise().squaredNorm(), nb = b.rowwise().squaredNorm();
  Eigen::MatrixXd d = (-2.0 * a * b.transpose()).colwise() + na;
  d.rowwise() += nb.transpose();
  return d.cwiseMax(0.0);
}

Eigen::MatrixXd Kernel(const Eigen::MatrixXd& squared_distances, double length_scale) {
  return (squared_distances * (-0.5 / (length_scale * length_scale))).array().exp().matrix();
}

class LinearRegressor : public PoseRegressor {
 public:
  explicit LinearRegressor(const LinearOptions& options) : options_(options) {}
  std::string Name() const override { return "LSQ"; }

  void Fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) override {
    CheckTraining(Name(), x, y, 2);
    const Eigen::Index d = x.cols();
    Eigen::MatrixXd a(x.rows(), d + 1);
    a << x, Eigen::VectorXd::Ones(x.rows());
    Eigen::MatrixXd normal = a.transpose() * a;
    normal.diagonal().head(d).array() += options_.ridge * std::max(1.0, normal.diagonal().head(d).mean());
    weights_ = normal.ldlt().solve(a.transpose() * y);
    NPHAND_THROW_CHECK(weights_.allFinite(), Name(), ": the normal equations have no finite solution");
    width_ = d;
  }

  Eigen::MatrixXd Predict(const Eigen::MatrixXd& x) const override {
    CheckQuery(Name(), width_, x);
    return (x * weights_.topRows(width_)).rowwise() + weights_.row(width_);
  }

 private:
  LinearOptions options_;
  Eigen::MatrixXd weights_;  // (d + 1) x m, the bias last
  Eigen::Index width_ = 0;
};

class GaussianProcess : public PoseRegressor {
 public:
  explicit GaussianProcess(const GaussianProcessOptions& options) : options_(options) {}
  std::string Name() const override { return "GP"; }

  void Fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) override {
    CheckTraining(Name(), x, y, 2);
    const double n = static_cast<double>(x.rows()), m = static_cast<double>(y.cols());
    mean_ = y.colwise().mean();
    const Eigen::MatrixXd centred = y.rowwise() - mean_;
    signal_ = centred.squaredNorm() / (n * m);
    if (!(signal_ > 0.0)) signal_ = 1.0;
    const Eigen::MatrixXd d2 = SquaredDistances(x, x);
    const double median = MedianDistance(x);
    bool found = false;
    summary_ = {};
    summary_.log_marginal = -std::numeric_limits<double>::infinity();
    for (double ls : options_.length_scales) {
      for (double nf : options_.noise_fractions) {
        const double length = ls * median, noise = nf * std::sqrt(signal_);
        Eigen::MatrixXd k = signal_ * Kernel(d2, length);
        k.diagonal().array() += noise * noise;
        const Eigen::LLT<Eigen::MatrixXd> llt(k);
        if (llt.info() != Eigen::Success) continue;
        const Eigen::MatrixXd alpha = llt.solve(centred);
        // log p(Y) = -1/2 tr(Y^T K^-1 Y) - m/2 log|K| - n m/2 log 2 pi, outputs independent.
        const double log_det = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
        const double log_marginal = -0.5 * (centred.array() * alpha.array()).sum() - 0.5 * m * log_det -
                                    0.5 * n * m * std::log(2.0 * std::numbers::pi);
        if (log_marginal > summary_.log_marginal) {
          summary_.log_marginal = log_marginal;
          summary_.length_scale = length;
          summary_.noise_sd = noise;
          alpha_ = alpha;
          found = true;
        }
      }
    }
    NPHAND_THROW_CHECK(found, Name(), ": no hyper-parameters gave a positive-definite kernel");
    train_ = x;
  }

  Eigen::MatrixXd Predict(const Eigen::MatrixXd& x) const override {
    CheckQuery(Name(), train_.cols(), x);
    const Eigen::MatrixXd k = signal_ * Kernel(SquaredDistances(x, train_), summary_.length_scale);
    return (k * alpha_).rowwise() + mean_;
  }

  RegressorSummary Summary() const override { return summary_; }

 private:
  GaussianProcessOptions options_;
  Eigen::MatrixXd train_, alpha_;  // n x d; K^-1 (Y - mean), n x m
  Eigen::RowVectorXd mean_;
  double signal_ = 1.0;
  RegressorSummary summary_;
};

class Rvm : public PoseRegressor {
 public:
  explicit Rvm(const RvmOptions& options) : options_(options) {}
  std::string Name() const override { return "RVM"; }

  void Fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) override {
    CheckTraining(Name(), x, y, 2);
    const Eigen::Index n = x.rows(), basis = n + 1;
    const double m = static_cast<double>(y.cols());
    summary_ = {};
    summary_.length_scale = options_.length_scale * MedianDistance(x);
    // The design: a bias, then the kernel on every training row.
    Eigen::MatrixXd phi(n, basis);
    phi << Eigen::VectorXd::Ones(n), Kernel(SquaredDistances(x, x), summary_.length_scale);
    const Eigen::MatrixXd gram = phi.transpose() * phi, phi_y = phi.transpose() * y;
    const double y_squares = y.squaredNorm();
    double variance = (y.rowwise() - y.colwise().mean()).squaredNorm() / (static_cast<double>(n) * m);
    if (!(variance > 0.0)) variance = 1.0;
    double beta = 100.0 / variance;  // noise precision, shared by the outputs
    Eigen::VectorXd alpha = Eigen::VectorXd::Constant(basis, 1.0);
    std::vector<Eigen::Index> active(basis);
    for (Eigen::Index i = 0; i < basis; ++i) active[i] = i;
    // Over the active basis functions: Phi_A^T Phi_A, Phi_A^T Y and the posterior precision
    // beta Phi_A^T Phi_A + diag(alpha_A).
    Eigen::MatrixXd sub_gram, projected, precision;
    auto restrict = [&]() {
      const Eigen::Index a = static_cast<Eigen::Index>(active.size());
      sub_gram.resize(a, a);
      projected.resize(a, y.cols());
      for (Eigen::Index r = 0; r < a; ++r) {
        for (Eigen::Index c = 0; c < a; ++c) sub_gram(r, c) = gram(active[r], active[c]);
        projected.row(r) = phi_y.row(active[r]);
      }
      precision = beta * sub_gram;
      for (Eigen::Index r = 0; r < a; ++r) precision(r, r) += alpha[active[r]];
    };
    Eigen::MatrixXd mu;
    for (summary_.iterations = 0; summary_.iterations < options_.iterations;) {
      ++summary_.iterations;
      const Eigen::Index a = static_cast<Eigen::Index>(active.size());
      restrict();
      const Eigen::LLT<Eigen::MatrixXd> llt(precision);
      NPHAND_THROW_CHECK(llt.info() == Eigen::Success, Name(), ": the posterior precision is not positive definite");
      const Eigen::MatrixXd sigma = llt.solve(Eigen::MatrixXd::Identity(a, a));
      mu = beta * sigma * projected;
      // ||Y - Phi mu||^2 from the Gram matrix: tr(Y^T Y) - 2 tr(mu^T Phi^T Y) + tr(mu^T G mu).
      const double residual =
          std::max(0.0, y_squares - 2.0 * (mu.array() * projected.array()).sum() + (mu.transpose() * sub_gram * mu).trace());
      double well_determined = 0.0, largest_step = 0.0;
      std::vector<Eigen::Index> kept;
      for (Eigen::Index r = 0; r < a; ++r) {
        const Eigen::Index i = active[r];
        const double gamma = std::clamp(1.0 - alpha[i] * sigma(r, r), 0.0, 1.0);
        well_determined += gamma;
        const double weight_squares = mu.row(r).squaredNorm();
        const double next = weight_squares > 0.0 ? m * gamma / weight_squares : std::numeric_limits<double>::infinity();
        if (std::isfinite(next) && next < options_.prune_alpha) {
          largest_step = std::max(largest_step, std::abs(std::log(next) - std::log(alpha[i])));
          alpha[i] = std::max(next, 1e-12);
          kept.push_back(i);
        }
      }
      NPHAND_THROW_CHECK(!kept.empty(), Name(), ": every basis function was pruned");
      beta = std::max(1e-12, (static_cast<double>(n) - well_determined) * m / std::max(residual, 1e-300));
      const bool pruned = kept.size() != active.size();
      active = kept;
      if (!pruned && largest_step < options_.tolerance) break;
    }
    // The weights of the basis functions that remain, from one last posterior over them.
    const Eigen::Index a = static_cast<Eigen::Index>(active.size());
    restrict();
    weights_ = beta * precision.llt().solve(projected);
    has_bias_ = active.front() == 0;
    relevant_.resize(a - (has_bias_ ? 1 : 0), x.cols());
    for (Eigen::Index r = has_bias_ ? 1 : 0, k = 0; r < a; ++r, ++k) relevant_.row(k) = x.row(active[r] - 1);
    summary_.basis = static_cast<int>(relevant_.rows());
    summary_.noise_sd = 1.0 / std::sqrt(beta);
    width_ = x.cols();
  }

  Eigen::MatrixXd Predict(const Eigen::MatrixXd& x) const override {
    CheckQuery(Name(), width_, x);
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(x.rows(), weights_.cols());
    if (has_bias_) out.rowwise() += weights_.row(0);
    if (relevant_.rows() > 0) {
      out += Kernel(SquaredDistances(x, relevant_), summary_.length_scale) * weights_.bottomRows(relevant_.rows());
    }
    return out;
  }

  RegressorSummary Summary() const override { return summary_; }

 private:
  RvmOptions options_;
  Eigen::MatrixXd relevant_;  // the relevance vectors' descriptors
  Eigen::MatrixXd weights_;   // (bias, if kept) then one row per relevance vector
  bool has_bias_ = false;
  Eigen::Index width_ = 0;
  RegressorSummary summary_;
};

}  // namespace

bool LinearOptions::Check(std::string* why) const {
  if (!(ridge >= 0.0 && ridge < 1.0)) return Fail(why, "the LSQ ridge must be within [0, 1)");
  return true;
}

bool GaussianProcessOptions::Check(std::string* why) const {
  if (length_scales.empty() || noise_fractions.empty()) return Fail(why, "the GP needs length scales and noise levels to search");
  for (double v : length_scales) {
    if (!(v > 0.0 && v < 1e6)) return Fail(why, "GP length scales must be positive multiples of the median distance");
  }
  for (double v : noise_fractions) {
    if (!(v > 0.0 && v < 1e3)) return Fail(why, "GP noise fractions must be positive");
  }
  return true;
}

bool RvmOptions::Check(std::string* why) const {
  if (!(length_scale > 0.0 && length_scale < 1e6)) return Fail(why, "the RVM length scale must be positive");
  if (iterations < 1 || iterations > 100000) return Fail(why, "RVM iterations must be within 1..100000");
  if (!(prune_alpha > 1.0) || !(tolerance > 0.0)) return Fail(why, "the RVM prune level must exceed 1 and its tolerance be positive");
  return true;
}

std::unique_ptr<PoseRegressor> MakeLinearRegressor(const LinearOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "lsq: ", why);
  return std::make_unique<LinearRegressor>(options);
}

std::unique_ptr<PoseRegressor> MakeGaussianProcess(const GaussianProcessOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "gp: ", why);
  return std::make_unique<GaussianProcess>(options);
}

std::unique_ptr<PoseRegressor> MakeRvm(const RvmOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "rvm: ", why);
  return std::make_unique<Rvm>(options);
}

double MedianDistance(const Eigen::MatrixXd& x, uint64_t seed) {
  const Eigen::Index n = x.rows();
  NPHAND_THROW_CHECK(n >= 2, "median distance: needs at least 2 rows");
  constexpr uint64_t kMaxPairs = 200000;
  std::vector<double> distances;
  const uint64_t pairs = static_cast<uint64_t>(n) * static_cast<uint64_t>(n - 1) / 2;
  if (pairs <= kMaxPairs) {
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = i + 1; j < n; ++j) distances.push_back((x.row(i) - x.row(j)).norm());
    }
  } else {
    Random random(seed);
    for (uint64_t p = 0; p < kMaxPairs; ++p) {
      const auto i = static_cast<Eigen::Index>(random.UniformIndex(n));
      auto j = static_cast<Eigen::Index>(random.UniformIndex(n - 1));
      if (j >= i) ++j;
      distances.push_back((x.row(i) - x.row(j)).norm());
    }
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double median = distances[distances.size() / 2];
  return median > 0.0 ? median : 1.0;
}

}  // namespace nphand

// The paper's regression baselines (Sec. 6, Fig. 6): a map from a descriptor to the pose
// vector, fitted on database entries, with no temporal model. One interface, three
// methods, all in Eigen:
//   LSQ  least-squares linear regression with a bias, y = W^T [x; 1]
//   GP   Gaussian-process regression, squared-exponential kernel, its length scale and
//        noise chosen by the marginal likelihood (Rasmussen & Williams, Alg. 2.1)
//   RVM  the relevance vector machine (Tipping 2001): the same kernel as a basis on the
//        training points, one precision per basis function shared by every output
//        (Thayananthan et al.'s multivariate form), re-estimated until most are pruned.
// Rows are samples: x is n x d, y is n x m.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace nphand {

// What a fitted regressor chose, for reports.
struct RegressorSummary {
  double length_scale = 0.0;    // GP, RVM: in the descriptor's units
  double noise_sd = 0.0;        // GP: chosen; RVM: estimated
  double log_marginal = 0.0;    // GP: of the chosen hyper-parameters
  int basis = 0;                // RVM: relevance vectors kept
  int iterations = 0;           // RVM: rounds run
};

class PoseRegressor {
 public:
  virtual ~PoseRegressor() = default;
  virtual std::string Name() const = 0;
  // Fits the map from the rows of x to the rows of y. Throws nphand::Error when their row
  // counts differ, or there are too few rows for the method.
  virtual void Fit(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) = 0;
  // The prediction for each row of x (rows x outputs). Throws nphand::Error before Fit, or
  // for rows of another width.
  virtual Eigen::MatrixXd Predict(const Eigen::MatrixXd& x) const = 0;
  // What the fit chose (zeros where a field does not apply).
  virtual RegressorSummary Summary() const { return {}; }
};

struct LinearOptions {
  double ridge = 1e-6;  // added to the normal equations' diagonal (bias excluded), for conditioning
  bool Check(std::string* why) const;
};

struct GaussianProcessOptions {
  // Hyper-parameters searched (every pair): length scales as multiples of the median
  // distance between training rows, noise standard deviations as fractions of the
  // targets' standard deviation. The signal variance is the targets' variance.
  std::vector<double> length_scales = {0.25, 0.5, 1.0, 2.0, 4.0};
  std::vector<double> noise_fractions = {0.01, 0.03, 0.1, 0.3};
  bool Check(std::string* why) const;
};

struct RvmOptions {
  double length_scale = 1.0;    // of the kernel basis, as a multiple of the median distance
  int iterations = 200;         // re-estimation rounds at most
  double prune_alpha = 1e9;     // a basis function whose precision exceeds this is dropped
  double tolerance = 1e-4;      // stop when no log precision moves by more than this
  bool Check(std::string* why) const;
};


std::unique_ptr<PoseRegressor> MakeLinearRegressor(const LinearOptions& options = {});
std::unique_ptr<PoseRegressor> MakeGaussianProcess(const GaussianProcessOptions& options = {});
std::unique_ptr<PoseRegressor> MakeRvm(const RvmOptions& options = {});

// The median Euclidean distance between the rows of x (over at most 200,000 pairs drawn
// with the seed when there are more): the scale the kernels' length scales multiply.
double MedianDistance(const Eigen::MatrixXd& x, uint64_t seed = 1);

}  // namespace nphand

// The hand segment as the features see it: a binary hand mask, wherever it came from (a
// rendered label image or a skin segmentation of a camera frame), cropped to the square
// around its bounding box with a margin and resampled to a fixed size.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace nphand {

struct CropOptions {
  int size = 64;         // side of the resampled crop, pixels
  double margin = 0.1;   // added on each side, as a fraction of the bounding box's longer side
  // Turn the mask first so that its principal axis is vertical (and its third moment along
  // it negative): in-plane rotation no longer changes the crop, and HandCrop::roll says how
  // far it was turned.
  bool normalize_roll = false;

  bool Check(std::string* why) const;
};

struct HandCrop {
  cv::Mat image;    // CV_32FC1, size x size, hand coverage in [0, 1]
  cv::Rect window;  // the square of the source image that was resampled (may extend past it);
                    // with normalize_roll, of the turned mask
  double roll = 0.0;  // radians the mask was turned counter-clockwise (as displayed) first
  // How sure the turn is of its direction: the third central moment along the principal
  // axis over the second's 3/2 power (the silhouette's skewness, >= 0). Near 0 the ends look
  // alike and the turn may be half a revolution off. 0 without roll normalisation.
  double roll_skewness = 0.0;
  // Source pixel (x, y) (OpenCV's convention: integers at pixel centres) to crop pixel:
  // the turn, the window and the resampling in one affine map.
  cv::Matx23d crop_from_image = cv::Matx23d(1, 0, 0, 0, 1, 0);
};

// `mask` turned counter-clockwise (as displayed) by `angle` radians about its centre, on a
// canvas large enough to lose nothing. Nearest-neighbour, so it stays binary.
cv::Mat RotateMask(const cv::Mat& mask, double angle);

// The counter-clockwise turn that makes the mask's principal axis vertical with its third
// moment along that axis negative (mass towards the top); 0 for an empty mask. If
// `skewness` is not null it receives the normalised third moment's magnitude along the axis.
double PrincipalRoll(const cv::Mat& mask, double* skewness = nullptr);

// The ratio of a silhouette's principal axes, >= 1: the square root of the ratio of its
// second central moments' eigenvalues (a w x h rectangle: h / w). `coverage` is a mask
// (CV_8UC1, non-zero = hand) or a crop's coverage (CV_32FC1); 1 when it is empty.
double Elongation(const cv::Mat& coverage);
// The crop of the non-zero pixels of `mask` (CV_8UC1); std::nullopt when the mask has none
// ("no hand"). Throws nphand::Error for a mask of another type or invalid options.
std::optional<HandCrop> CropHand(const cv::Mat& mask, const CropOptions& options = {});

// The crop turned by half a revolution (roll + pi): the other reading of a silhouette whose
// ends look alike (small roll_skewness).
HandCrop HalfTurn(const HandCrop& crop);

// The affine map of 2 x 3 matrices a after b.
cv::Matx23d Compose(const cv::Matx23d& a, const cv::Matx23d& b);

// The crop turned by `angle` radians counter-clockwise (as displayed) about its centre
// (bilinear; what leaves the square is lost, the corners it uncovers are empty): another
// reading of a silhouette whose principal axis may be off, as stray pieces of a segmented
// hand, a cut forearm or an object's hole turn it. Its roll and map follow the turn.
HandCrop TiltCrop(const HandCrop& crop, double angle);

}  // namespace nphand

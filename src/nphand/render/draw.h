// Drawing overlays for people to look at: the 21 keypoints and their skeleton.
#pragma once

#include <array>
#include <filesystem>

#include <opencv2/core.hpp>

#include "nphand/model/hand_model.h"
#include "nphand/render/camera.h"

namespace nphand {

// Draws the keypoints (camera frame, metres) and the bones between them on a BGR image.
void DrawKeypoints(const Intrinsics& intrinsics, const Keypoints3d& keypoints_in_camera, cv::Mat* bgr);
// The same from keypoints already in pixels (pixel centres at +0.5).
void DrawKeypoints2d(const std::array<Eigen::Vector2d, kNumKeypoints>& keypoints, cv::Mat* bgr);

// `image` (8-bit BGR) scaled to fit `size` with its aspect kept, centred on a `border`
// background: one frame size for a video, one tile of a contact sheet. `scale` and `offset`
// (if not null) receive the map from image pixels to the result's: p * scale + offset.
cv::Mat FitInto(const cv::Mat& image, cv::Size size, cv::Scalar border, double* scale = nullptr, cv::Point* offset = nullptr);

// A label image (PixelLabel values) as a grey picture: background black, hand white, object grey.
cv::Mat LabelsForDisplay(const cv::Mat& labels);

}  // namespace nphand

namespace nphand {

// Encodes `image` by the extension of `path` (.png, .jpg, …) and writes it atomically.
void WriteImageAtomic(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace nphand

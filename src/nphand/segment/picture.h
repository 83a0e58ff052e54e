// The picture within a frame: letterboxed or pillarboxed video (a phone's upright clip in a
// wide frame) holds its picture between two black bars, one along each of two opposite
// sides. A hand's arm that leaves the picture ends at a bar, not at the frame's edge; the
// estimator reads the picture's edge as the frame's (a region that reaches it enters from
// outside).
#pragma once

#include <opencv2/core.hpp>

namespace nphand {

// A dark pixel: no channel brighter than kBarLevel (8-bit). A bar's line is at least
// kBarShare dark (compression noise lifts a few pixels).
inline constexpr int kBarLevel = 24;
inline constexpr double kBarShare = 0.99;
// A bar is at least kBarLeast lines deep (one black line is an edge of the scene) and less
// than kBarMost of the frame's side (deeper: a dark scene).
inline constexpr int kBarLeast = 2;
inline constexpr double kBarMost = 0.34;
// A bar ends in a straight edge: within kBarEdge of the side's length past its last line (at
// least kBarEdgeLeast lines: compression and scaling blur the edge) a line is at most
// kPictureDark dark. A dark scene's edge is not straight, and its dark goes on.
inline constexpr double kBarEdge = 0.02;
inline constexpr int kBarEdgeLeast = 3;
inline constexpr double kPictureDark = 0.1;
// Bars are paired: the opposite side's bar is as deep, within this share of the side (a
// dark scene along one side has no twin).
inline constexpr double kBarPairing = 0.02;

// The frame (CV_8UC3) less its paired black bars, each side's picture starting at the first
// line past its bar's edge; the whole frame without bars. A side's lines are read over the
// middle third of their length (the bars across them lie outside it). Throws nphand::Error
// for another type or an empty frame.
cv::Rect PictureOf(const cv::Mat& bgr);

}  // namespace nphand

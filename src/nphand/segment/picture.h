// The picture within a frame: letterboxed or pillarboxed video (a phone's upright clip in a
// wide frame, a wide film in a 4:3 one) holds its picture between two black bars, one along
// each of two opposite sides. A hand's arm that leaves the picture ends at a bar, not at the
// frame's edge. The estimator therefore takes the picture for the frame when it chooses and
// gathers the hand's region and when the forearm cut asks where an arm enters from outside
// (the skin segmentation still reads the whole frame: a skin-coloured body below a face is
// set aside where it meets the frame's bottom edge, not a bar's).
#pragma once

#include <opencv2/core.hpp>

namespace nphand {

// A dark pixel: no channel brighter than kBarLevel (8-bit). A bar's line is at least
// kBarShare dark (compression noise lifts a few pixels).
inline constexpr int kBarLevel = 24;
inline constexpr double kBarShare = 0.99;
// A bar is at least kBarLeast lines deep (one black line is an edge of the scene) and less
// than kBarMost of the frame's side (deeper: a dark scene). A 9:16 clip in a 16:9 frame
// leaves bars of 0.342 of its width, in a 21:9 one 0.38.
inline constexpr int kBarLeast = 2;
inline constexpr double kBarMost = 0.4;
// A bar ends in a straight edge: among the lines that follow it, kBarEdge of the side (at
// least kBarEdgeLeast: compression and scaling blur the edge), one is at most kPictureDark
// dark, and the picture starts there. A dark scene's edge is not straight, and its dark
// goes on.
inline constexpr double kBarEdge = 0.02;
inline constexpr int kBarEdgeLeast = 3;
inline constexpr double kPictureDark = 0.1;
// Bars are paired: the opposite side's bar is as deep, within this share of the side (a
// dark scene along one side has no twin).
inline constexpr double kBarPairing = 0.02;

// The frame (CV_8UC3) less its paired black bars, each side's picture starting past its
// bar's edge; the whole frame without bars (a frame under 8 pixels across has none). A
// side's lines are read over the middle fifth of their length, which no bar across them
// reaches. Throws nphand::Error for another type or an empty frame.
cv::Rect PictureOf(const cv::Mat& bgr);

}  // namespace nphand

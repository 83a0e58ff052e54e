#include "nphand/segment/picture.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// The share of the `count` pixels from `at`, `step` bytes apart, that are dark.
double DarkShare(const uint8_t* at, int count, size_t step) {
  int dark = 0;
  for (int i = 0; i < count; ++i, at += step) dark += std::max({at[0], at[1], at[2]}) <= kBarLevel;
  return static_cast<double>(dark) / count;
}

// Where the picture starts along one side, in lines from the frame's edge (0: no bar). Line
// i of the side's `lines` starts at `first + i * next` and runs `count` pixels `step` bytes
// apart.
int PictureStart(const uint8_t* first, ptrdiff_t next, int lines, int count, size_t step) {
  const int most = static_cast<int>(kBarMost * lines);
  int depth = 0;
  while (depth < most && DarkShare(first + depth * next, count, step) >= kBarShare) ++depth;
  if (depth < kBarLeast || depth >= most) return 0;
  const int edge = std::max(kBarEdgeLeast, static_cast<int>(kBarEdge * lines));
  for (int line = depth; line <= std::min(depth + edge, lines - 1); ++line) {
    if (DarkShare(first + line * next, count, step) <= kPictureDark) return line;
  }
  return 0;
}

}  // namespace

cv::Rect PictureOf(const cv::Mat& bgr) {
  NPHAND_THROW_CHECK(!bgr.empty() && bgr.type() == CV_8UC3, "picture: a frame must be a non-empty 8-bit BGR image");
  const int w = bgr.cols, h = bgr.rows;
  const size_t row = bgr.step[0], pixel = 3;
  const ptrdiff_t back_row = -static_cast<ptrdiff_t>(row), back_pixel = -static_cast<ptrdiff_t>(pixel);
  // Each side's lines are read over the middle third of their length, which the bars across
  // them (each under kBarMost of the frame) leave alone.
  const int rows = std::max(1, h / 3), cols = std::max(1, w / 3);
  const uint8_t* middle_rows = bgr.ptr<uint8_t>(h / 3);
  const uint8_t* middle_cols = bgr.ptr<uint8_t>(0) + (w / 3) * pixel;
  const int left = PictureStart(middle_rows, pixel, w, rows, row);
  const int right = PictureStart(middle_rows + (w - 1) * pixel, back_pixel, w, rows, row);
  const int top = PictureStart(middle_cols, row, h, cols, pixel);
  const int bottom = PictureStart(middle_cols + (h - 1) * row, back_row, h, cols, pixel);
  // Bars come in pairs about the picture: one alone is a dark scene's side.
  auto paired = [](int a, int b, int side) { return a > 0 && b > 0 && std::abs(a - b) <= kBarPairing * side; };
  const bool across = paired(left, right, w), down = paired(top, bottom, h);
  const cv::Rect picture(across ? left : 0, down ? top : 0, across ? w - left - right : w, down ? h - top - bottom : h);
  return picture.width > 0 && picture.height > 0 ? picture : cv::Rect(0, 0, w, h);
}

}  // namespace nphand

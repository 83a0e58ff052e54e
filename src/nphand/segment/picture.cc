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
  for (int i = 0; i < count; ++i) {
    const uint8_t* pixel = at + i * step;
    dark += std::max({pixel[0], pixel[1], pixel[2]}) <= kBarLevel;
  }
  return static_cast<double>(dark) / count;
}

// One side's bar, in lines from the frame's edge: its depth (0: no bar) and where the
// picture starts past its edge.
struct Bar {
  int depth = 0;
  int start = 0;
};

// The bar along one side of `lines` lines: line i starts at `first + i * next` and is read
// over `count` pixels `step` bytes apart.
Bar BarAlong(const uint8_t* first, ptrdiff_t next, int lines, int count, size_t step) {
  const int most = static_cast<int>(kBarMost * lines);
  int depth = 0;
  while (depth < most && DarkShare(first + depth * next, count, step) >= kBarShare) ++depth;
  if (depth < kBarLeast || depth >= most) return {};
  // depth + edge <= lines (kBarMost + kBarEdge < 1, and a bar needs lines >= 8).
  const int edge = std::max(kBarEdgeLeast, static_cast<int>(kBarEdge * lines));
  for (int line = depth; line < depth + edge; ++line) {
    if (DarkShare(first + line * next, count, step) <= kPictureDark) return {depth, line};
  }
  return {};
}

}  // namespace

cv::Rect PictureOf(const cv::Mat& bgr) {
  NPHAND_THROW_CHECK(!bgr.empty() && bgr.type() == CV_8UC3, "picture: a frame must be a non-empty 8-bit BGR image");
  const int w = bgr.cols, h = bgr.rows;
  const size_t row = bgr.step[0], pixel = 3;
  const ptrdiff_t back_row = -static_cast<ptrdiff_t>(row), back_pixel = -static_cast<ptrdiff_t>(pixel);
  // Each side's lines are read where no bar across them can reach: past kBarMost of the
  // side from either end (the middle fifth), at least one pixel.
  const int skip_rows = std::min(static_cast<int>(kBarMost * h), (h - 1) / 2);
  const int skip_cols = std::min(static_cast<int>(kBarMost * w), (w - 1) / 2);
  const int rows = h - 2 * skip_rows, cols = w - 2 * skip_cols;
  const uint8_t* middle_rows = bgr.ptr<uint8_t>(skip_rows);
  const uint8_t* middle_cols = bgr.ptr<uint8_t>(0) + skip_cols * pixel;
  const Bar left = BarAlong(middle_rows, pixel, w, rows, row);
  const Bar right = BarAlong(middle_rows + (w - 1) * pixel, back_pixel, w, rows, row);
  const Bar top = BarAlong(middle_cols, row, h, cols, pixel);
  const Bar bottom = BarAlong(middle_cols + (h - 1) * row, back_row, h, cols, pixel);
  // Bars come in pairs about the picture: one alone is a dark scene's side.
  auto paired = [](const Bar& a, const Bar& b, int side) {
    return a.depth > 0 && b.depth > 0 && std::abs(a.depth - b.depth) <= kBarPairing * side;
  };
  const bool across = paired(left, right, w), down = paired(top, bottom, h);
  const cv::Rect picture(across ? left.start : 0, down ? top.start : 0, across ? w - left.start - right.start : w,
                         down ? h - top.start - bottom.start : h);
  // Each side's start is the first line no more than kPictureDark dark, the lines before it
  // darker, read over the same pixels from both sides: the starts cannot cross.
  NPHAND_CHECK(picture.width > 0 && picture.height > 0, "picture: the bars' starts crossed");
  return picture;
}

}  // namespace nphand

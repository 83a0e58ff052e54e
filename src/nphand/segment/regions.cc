#include "nphand/segment/regions.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {

std::vector<MaskRun> Runs(const cv::Mat& mask) {
  NPHAND_THROW_CHECK(!mask.empty() && mask.type() == CV_8UC1, "regions: the mask must be a non-empty 8-bit single-channel image");
  std::vector<MaskRun> runs;
  const int width = mask.cols;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(y);
    int x = 0;
    while (x < width) {
      // Eight background pixels at a time.
      if (x + 8 <= width) {
        uint64_t eight = 0;
        std::memcpy(&eight, row + x, sizeof(eight));
        if (eight == 0) {
          x += 8;
          continue;
        }
      }
      if (row[x] == 0) {
        ++x;
        continue;
      }
      int end = x + 1;
      while (end < width && row[end] != 0) ++end;
      runs.push_back({y, x, end - 1});
      x = end;
    }
  }
  return runs;
}

std::vector<RegionStats> LabelRegions(const cv::Mat& mask, cv::Mat* labels, int connectivity) {
  NPHAND_THROW_CHECK(connectivity == 4 || connectivity == 8, "regions: connectivity must be 4 or 8, not ", connectivity);
  const std::vector<MaskRun> runs = Runs(mask);
  const int count = cv::connectedComponents(mask, *labels, connectivity, CV_32S);
  struct Sums {
    int64_t area = 0, x = 0, y = 0;
    int x0 = std::numeric_limits<int>::max(), x1 = -1, y1 = -1;
    cv::Point first;  // its first run's first pixel: the box's top row
  };
  std::vector<Sums> sums(count);
  for (const MaskRun& r : runs) {
    Sums& s = sums[labels->at<int>(r.y, r.x0)];  // a run is one region's: its pixels touch
    const int64_t n = r.x1 - r.x0 + 1;
    if (s.area == 0) s.first = cv::Point(r.x0, r.y);
    s.area += n;
    s.x += (static_cast<int64_t>(r.x0) + r.x1) * n / 2;  // x0 + (x0 + 1) + ... + x1
    s.y += r.y * n;
    s.x0 = std::min(s.x0, r.x0);
    s.x1 = std::max(s.x1, r.x1);
    s.y1 = r.y;
  }
  std::vector<RegionStats> stats(count);
  for (int label = 1; label < count; ++label) {
    const Sums& s = sums[label];
    RegionStats& r = stats[label];
    r.area = static_cast<int>(s.area);
    r.box = cv::Rect(s.x0, s.first.y, s.x1 - s.x0 + 1, s.y1 - s.first.y + 1);
    r.centroid = cv::Point2d(static_cast<double>(s.x) / s.area, static_cast<double>(s.y) / s.area);
    r.first = s.first;
  }
  return stats;
}

cv::Rect HandReach(const cv::Rect& box) {
  const int grow = static_cast<int>(0.3 * std::max(box.width, box.height));
  return cv::Rect(box.x - grow, box.y - grow, box.width + 2 * grow, box.height + 2 * grow);
}

}  // namespace nphand

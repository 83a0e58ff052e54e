#include "nphand/segment/regions.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {

std::vector<RegionStats> LabelRegions(const cv::Mat& mask, cv::Mat* labels) {
  NPHAND_THROW_CHECK(!mask.empty() && mask.type() == CV_8UC1, "regions: the mask must be a non-empty 8-bit single-channel image");
  const int count = cv::connectedComponents(mask, *labels, 8, CV_32S);
  struct Sums {
    int64_t area = 0, x = 0, y = 0;
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  };
  std::vector<Sums> sums(count);
  const int width = mask.cols;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* in = mask.ptr<uint8_t>(y);
    const int* row = labels->ptr<int>(y);
    int x = 0;
    while (x < width) {
      // Eight background pixels at a time.
      if (x + 8 <= width) {
        uint64_t eight = 0;
        std::memcpy(&eight, in + x, sizeof(eight));
        if (eight == 0) {
          x += 8;
          continue;
        }
      }
      if (in[x] == 0) {
        ++x;
        continue;
      }
      const int label = row[x];
      int end = x + 1;
      while (end < width && row[end] == label) ++end;
      Sums& s = sums[label];
      const int64_t run = end - x;
      if (s.area == 0) {
        s.x0 = x;
        s.y0 = y;
        s.x1 = end - 1;
      }
      s.area += run;
      s.x += (x + end - 1) * run / 2;  // x + (x + 1) + ... + (end - 1)
      s.y += y * run;
      s.x0 = std::min(s.x0, x);
      s.x1 = std::max(s.x1, end - 1);
      s.y1 = y;
      x = end;
    }
  }
  std::vector<RegionStats> stats(count);
  for (int label = 1; label < count; ++label) {
    const Sums& s = sums[label];
    RegionStats& r = stats[label];
    r.area = static_cast<int>(s.area);
    r.box = cv::Rect(s.x0, s.y0, s.x1 - s.x0 + 1, s.y1 - s.y0 + 1);
    r.centroid = cv::Point2d(static_cast<double>(s.x) / s.area, static_cast<double>(s.y) / s.area);
  }
  return stats;
}

}  // namespace nphand

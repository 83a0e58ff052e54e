#include "nphand/segment/forearm.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "nphand/segment/regions.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

struct Profile {
  std::vector<double> width;  // extent across the axis per 1-pixel slice, smoothed
  double t0 = 0.0;            // axis coordinate of slice 0
};

// Which sides of the slice at one end touch the frame: counts of the end's pixels that lie
// on a bordering edge.
int EndTouches(const std::vector<cv::Point>& points, const std::vector<double>& t, double from, double to, int border,
               const cv::Size& size) {
  int touches = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (t[i] < from || t[i] > to) continue;
    const cv::Point& p = points[i];
    touches += ((border & 1) && p.x == 0) || ((border & 2) && p.y == 0) || ((border & 4) && p.x == size.width - 1) ||
               ((border & 8) && p.y == size.height - 1);
  }
  return touches;
}

}  // namespace

bool ForearmCutOptions::Check(std::string* why) const {
  if (!(widen_ratio > 1.0 && widen_ratio < 5.0) || !(min_arm_width > 0.0 && min_arm_width < 1.0) ||
      !(min_arm_length >= 0.0 && min_arm_length < 10.0) || !(min_arm_length_at_edge >= 0.0 && min_arm_length_at_edge < 10.0) ||
      !(wrist_reach > 0.0 && wrist_reach <= 10.0)) {
    *why = "forearm cut needs widen ratio in (1, 5), arm width in (0, 1), arm lengths in [0, 10) and wrist reach in (0, 10]";
    return false;
  }
  return true;
}

namespace {

// One reading of the region along an axis: the width profile, and where the wrist is.
struct Reading {
  int direction = 0;          // +1: the arm is at the low end of the axis; -1: the high end; 0: no arm
  double cut_t = 0.0;         // axis coordinate of the cut
  double wrist_width = 0.0;
  cv::Point2d wrist;          // the cut's centre
  cv::Point2d centre, axis;   // the axis: through `centre` along `axis` (unit)
  std::vector<double> t;      // each point's axis coordinate
};

// The region's points read along `axis` through `centre`.
Reading Read(const std::vector<cv::Point>& points, cv::Point2d centre, cv::Point2d axis, int border,
             const cv::Size& size, const ForearmCutOptions& options) {
  Reading r;
  r.centre = centre;
  r.axis = axis;
  const cv::Point2d across(-axis.y, axis.x);
  r.t.resize(points.size());
  std::vector<double> s(points.size());
  double t_min = 1e300, t_max = -1e300;
  for (size_t i = 0; i < points.size(); ++i) {
    const cv::Point2d d = cv::Point2d(points[i]) - centre;
    r.t[i] = d.dot(axis);
    s[i] = d.dot(across);
    t_min = std::min(t_min, r.t[i]);
    t_max = std::max(t_max, r.t[i]);
  }
  const int slices = static_cast<int>(std::floor(t_max - t_min)) + 1;
  if (slices < 8) return r;
  std::vector<double> low(slices, 1e300), high(slices, -1e300);
  for (size_t i = 0; i < points.size(); ++i) {
    const int k = std::min(slices - 1, static_cast<int>(r.t[i] - t_min));
    low[k] = std::min(low[k], s[i]);
    high[k] = std::max(high[k], s[i]);
  }
  std::vector<double> raw(slices, 0.0);
  for (int k = 0; k < slices; ++k) raw[k] = high[k] >= low[k] ? high[k] - low[k] + 1.0 : 0.0;
  // Smooth over about 3 % of the length so that one ragged slice does not decide.
  const int half = std::max(1, slices / 60);
  std::vector<double> width(slices, 0.0);
  for (int k = 0; k < slices; ++k) {
    double sum = 0.0;
    int n = 0;
    for (int j = std::max(0, k - half); j <= std::min(slices - 1, k + half); ++j, ++n) sum += raw[j];
    width[k] = sum / n;
  }
  const double widest = *std::max_element(width.begin(), width.end());
  const double reach = 0.05 * slices;
  const int touch_low = EndTouches(points, r.t, t_min, t_min + reach, border, size);
  const int touch_high = EndTouches(points, r.t, t_max - reach, t_max, border, size);

  // From one end (direction +1: from t_min), the narrow stretch's end before the widening
  // (steps from that end), or -1.
  auto find_wrist = [&](int direction, double* wrist_width) {
    auto index = [&](int step) { return direction > 0 ? step : slices - 1 - step; };
    // Skip the end's cap, where the width still grows: a rounded end, or an arm that leaves
    // the frame obliquely, whose cut edge can rise unevenly, so there the cap lasts until
    // the width is near that of the stretch beyond it.
    const bool at_edge = (direction > 0 ? touch_low : touch_high) > 0;
    int first = 0;
    while (first + 1 < slices && width[index(first + 1)] > 1.02 * width[index(first)]) ++first;
    if (at_edge) {
      const int ahead = std::max(3, slices / 20);
      for (; first + ahead < slices; ++first) {
        std::vector<double> next;
        for (int j = first + 1; j <= first + ahead; ++j) next.push_back(width[index(j)]);
        std::nth_element(next.begin(), next.begin() + next.size() / 2, next.end());
        if (width[index(first)] >= 0.9 * next[next.size() / 2]) break;
      }
    }
    // The hand starts where the width first exceeds widen_ratio times the narrowest seen.
    double narrowest = 1e300;
    int hand_start = -1;
    for (int step = first; step < slices; ++step) {
      const double w = width[index(step)];
      if (step > first && w > options.widen_ratio * narrowest) {
        hand_start = step;
        break;
      }
      narrowest = std::min(narrowest, w);
    }
    if (hand_start < 0) return -1;
    // The arm's width is the median of its stretch: an arm seen in perspective tapers, and
    // its rounded end's last slices are still narrow, so its narrowest slice may lie at the
    // far end. The wrist is the narrowest place just before the hand: within wrist_reach
    // arm widths of it, cut where the narrow stretch (within 1 % of the arm's width) ends.
    std::vector<double> stretch;
    for (int step = first; step < hand_start; ++step) stretch.push_back(width[index(step)]);
    std::nth_element(stretch.begin(), stretch.begin() + stretch.size() / 2, stretch.end());
    const double arm = stretch[stretch.size() / 2];
    const int from = std::max(first, hand_start - std::max(3, static_cast<int>(std::lround(options.wrist_reach * arm))));
    double wrist = 1e300;
    int at = from;
    for (int step = from; step < hand_start; ++step) {
      const double w = width[index(step)];
      if (w < wrist) {
        wrist = w;
        at = step;
      } else if (w <= wrist + 0.01 * arm) {
        at = step;
      }
    }
    *wrist_width = wrist;
    // An arm: long enough before the cut and not as thin as a finger.
    const double length = at_edge ? options.min_arm_length_at_edge : options.min_arm_length;
    if (at >= length * arm && arm >= options.min_arm_width * widest) return at;
    return -1;
  };
  double width_low = 0.0, width_high = 0.0;
  const int from_low = find_wrist(+1, &width_low);
  const int from_high = find_wrist(-1, &width_high);
  if (from_low >= 0 && from_high >= 0) {
    // Both ends could be an arm: the one entering from the frame's edge, else the longer run.
    if (touch_low != touch_high) {
      r.direction = touch_low > touch_high ? +1 : -1;
    } else {
      r.direction = from_low >= from_high ? +1 : -1;
    }
  } else if (from_low >= 0) {
    r.direction = +1;
  } else if (from_high >= 0) {
    r.direction = -1;
  }
  if (r.direction == 0) return r;
  const int step = r.direction > 0 ? from_low : from_high;
  r.wrist_width = r.direction > 0 ? width_low : width_high;
  r.cut_t = r.direction > 0 ? t_min + step + 0.5 : t_max - step - 0.5;
  const int k = std::clamp(static_cast<int>(r.cut_t - t_min), 0, slices - 1);
  r.wrist = centre + axis * r.cut_t + across * (0.5 * (low[k] + high[k]));
  return r;
}

bool OnArmSide(const Reading& r, double t) { return r.direction > 0 ? t < r.cut_t : t > r.cut_t; }

}  // namespace

ForearmCut CutForearm(const cv::Mat& region, int border, const ForearmCutOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "forearm: ", why);
  NPHAND_THROW_CHECK(!region.empty() && region.type() == CV_8UC1, "forearm: a region must be an 8-bit single-channel mask");
  ForearmCut result;
  result.hand = region != 0;
  std::vector<cv::Point> points;
  cv::findNonZero(result.hand, points);
  if (points.size() < 50) return result;

  const cv::Moments m = cv::moments(result.hand, true);
  const double angle = 0.5 * std::atan2(2.0 * m.mu11, m.mu20 - m.mu02);
  const Reading reading = Read(points, cv::Point2d(m.m10 / m.m00, m.m01 / m.m00), cv::Point2d(std::cos(angle), std::sin(angle)),
                               border, region.size(), options);
  if (reading.direction == 0) return result;
  for (size_t i = 0; i < points.size(); ++i) {
    if (OnArmSide(reading, reading.t[i])) result.hand.at<uint8_t>(points[i]) = 0;
  }
  // The cut may leave crumbs of the arm's edge: keep the largest piece.
  cv::Mat labels;
  const std::vector<RegionStats> pieces = LabelRegions(result.hand, &labels);
  if (pieces.size() > 2) {
    size_t best = 1;
    for (size_t l = 2; l < pieces.size(); ++l) {
      if (pieces[l].area > pieces[best].area) best = l;
    }
    result.hand = labels == static_cast<int>(best);
  }
  result.cut = true;
  result.wrist_width = reading.wrist_width;
  result.wrist = reading.wrist;
  result.arm_direction = reading.direction > 0 ? -reading.axis : reading.axis;
  return result;
}

}  // namespace nphand

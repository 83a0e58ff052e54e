#include "nphand/segment/forearm.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "nphand/segment/regions.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

// The region's centroid and principal axis angle from its second moments, computed as
// cv::moments computes them for a binary image (the raw moments are exact integers), so
// that the axis is OpenCV's to the last bit. From the runs the cut reads anyway: cv::moments
// is one more pass over the mask, a quarter of the cut's time.
struct Axis {
  int64_t pixels = 0;
  cv::Point2d centre;
  double angle = 0.0;
};

Axis AxisOf(const std::vector<MaskRun>& runs) {
  int64_t m00 = 0, m10 = 0, m01 = 0, m20 = 0, m02 = 0, m11 = 0;
  auto squares_to = [](int64_t k) { return k * (k + 1) * (2 * k + 1) / 6; };  // 0^2 + ... + k^2
  for (const MaskRun& r : runs) {
    const int64_t n = r.x1 - r.x0 + 1, sum_x = (static_cast<int64_t>(r.x0) + r.x1) * n / 2;
    m00 += n;
    m10 += sum_x;
    m01 += r.y * n;
    m20 += squares_to(r.x1) - squares_to(r.x0 - 1);
    m02 += static_cast<int64_t>(r.y) * r.y * n;
    m11 += r.y * sum_x;
  }
  Axis axis;
  axis.pixels = m00;
  if (m00 == 0) return axis;
  const double d00 = static_cast<double>(m00), d10 = static_cast<double>(m10), d01 = static_cast<double>(m01);
  const double inv_m00 = 1.0 / d00, cx = d10 * inv_m00, cy = d01 * inv_m00;
  const double mu20 = static_cast<double>(m20) - d10 * cx, mu11 = static_cast<double>(m11) - d10 * cy,
               mu02 = static_cast<double>(m02) - d01 * cy;
  axis.centre = cv::Point2d(d10 / d00, d01 / d00);
  axis.angle = 0.5 * std::atan2(2.0 * mu11, mu20 - mu02);
  return axis;
}

// A pixel's coordinates along the axis (t) and across it (s).
struct Frame {
  cv::Point2d centre, axis, across;
  double T(int x, int y) const { return (x - centre.x) * axis.x + (y - centre.y) * axis.y; }
  double S(int x, int y) const { return (x - centre.x) * across.x + (y - centre.y) * across.y; }
};

// How the region meets the frame's edge at its two ends: counts of the edge pixels within
// `reach` of each end, and how far along the axis from each end its contact with the edge
// goes (the stretches of edge pixels, unbroken along a side of the frame, that begin within
// `reach` of the end): an arm leaving the frame obliquely is cut by the edge over that
// stretch, where its slices are not its width.
struct EdgeContact {
  int touch_low = 0, touch_high = 0;
  double cap_low = 0.0, cap_high = 0.0;
};

EdgeContact ContactOf(const std::vector<MaskRun>& runs, const Frame& f, double t_min, double t_max, double reach, int border,
                      const cv::Size& size) {
  EdgeContact c;
  auto touch = [&](int x, int y) {
    const double t = f.T(x, y);
    c.touch_low += t <= t_min + reach;
    c.touch_high += t >= t_max - reach;
  };
  // A stretch along the edge from (x0, y0) to (x1, y1): t is linear along it.
  auto stretch = [&](int x0, int y0, int x1, int y1) {
    const double a = f.T(x0, y0), b = f.T(x1, y1), low = std::min(a, b), high = std::max(a, b);
    if (low <= t_min + reach) c.cap_low = std::max(c.cap_low, high - t_min);
    if (high >= t_max - reach) c.cap_high = std::max(c.cap_high, t_max - low);
  };
  // Along the left and right sides a stretch is the rows, while consecutive, whose runs touch it.
  struct Side {
    int x, from = -1, last = -2;
  };
  auto extend = [&](Side& side, int y) {
    if (y != side.last + 1) {
      if (side.from >= 0) stretch(side.x, side.from, side.x, side.last);
      side.from = y;
    }
    side.last = y;
  };
  Side left{0}, right{size.width - 1};
  for (const MaskRun& r : runs) {
    const bool at_left = (border & 1) && r.x0 == 0, at_right = (border & 4) && r.x1 == right.x;
    if (((border & 2) && r.y == 0) || ((border & 8) && r.y == size.height - 1)) {
      for (int x = r.x0; x <= r.x1; ++x) touch(x, r.y);
      stretch(r.x0, r.y, r.x1, r.y);
    } else {
      if (at_left) touch(r.x0, r.y);
      if (at_right && !(at_left && r.x0 == r.x1)) touch(r.x1, r.y);
    }
    if (at_left) extend(left, r.y);
    if (at_right) extend(right, r.y);
  }
  for (const Side& side : {left, right}) {
    if (side.from >= 0) stretch(side.x, side.from, side.x, side.last);
  }
  return c;
}

}  // namespace

bool ForearmCutOptions::Check(std::string* why) const {
  if (!(widen_ratio > 1.0 && widen_ratio < 5.0) || !(widen_within > 0.0 && widen_within <= 100.0) ||
      !(min_arm_width > 0.0 && min_arm_width < 1.0) ||
      !(min_arm_length >= 0.0 && min_arm_length < 10.0) || !(min_arm_length_at_edge >= 0.0 && min_arm_length_at_edge < 10.0) ||
      !(wrist_reach > 0.0 && wrist_reach <= 10.0)) {
    *why = "forearm cut needs widen ratio in (1, 5), widening stretch in (0, 100], arm width in (0, 1), arm lengths in [0, 10) and wrist reach in (0, 10]";
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
};

// The region's runs read along `axis` through `centre`.
Reading Read(const std::vector<MaskRun>& runs, cv::Point2d centre, cv::Point2d axis, int border, const cv::Size& size,
             const ForearmCutOptions& options) {
  Reading r;
  r.centre = centre;
  r.axis = axis;
  const cv::Point2d across(-axis.y, axis.x);
  const Frame f{centre, axis, across};
  double t_min = 1e300, t_max = -1e300;
  for (const MaskRun& run : runs) {
    for (int x = run.x0; x <= run.x1; ++x) {
      const double t = f.T(x, run.y);
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
    }
  }
  const int slices = static_cast<int>(std::floor(t_max - t_min)) + 1;
  if (slices < 8) return r;
  std::vector<double> low(slices, 1e300), high(slices, -1e300), filled(slices, 0.0);
  for (const MaskRun& run : runs) {
    for (int x = run.x0; x <= run.x1; ++x) {
      const int k = std::min(slices - 1, static_cast<int>(f.T(x, run.y) - t_min));
      const double s = f.S(x, run.y);
      low[k] = std::min(low[k], s);
      high[k] = std::max(high[k], s);
      filled[k] += 1.0;
    }
  }
  std::vector<double> raw(slices, 0.0);
  for (int k = 0; k < slices; ++k) raw[k] = high[k] >= low[k] ? high[k] - low[k] + 1.0 : 0.0;
  // Smooth over about 3 % of the length so that one ragged slice does not decide.
  const int half = std::max(1, slices / 60);
  auto smooth = [&](const std::vector<double>& in) {
    std::vector<double> out(slices, 0.0);
    for (int k = 0; k < slices; ++k) {
      double sum = 0.0;
      int n = 0;
      for (int j = std::max(0, k - half); j <= std::min(slices - 1, k + half); ++j, ++n) sum += in[j];
      out[k] = sum / n;
    }
    return out;
  };
  const std::vector<double> width = smooth(raw);
  // The widest part, as the 90th percentile of the slices' skin (their pixels, not their
  // extent): a thumb and a little finger held out sideways (the "call" sign) make slices
  // whose extent is far wider than the palm, next to which the arm would pass for a finger.
  std::vector<double> sorted = smooth(filled);
  const size_t percentile = (sorted.size() - 1) * 9 / 10;
  std::nth_element(sorted.begin(), sorted.begin() + percentile, sorted.end());
  const double widest = sorted[percentile];
  const double reach = 0.05 * slices;
  const EdgeContact contact = ContactOf(runs, f, t_min, t_max, reach, border, size);
  const int touch_low = contact.touch_low, touch_high = contact.touch_high;

  // From one end (direction +1: from t_min), the narrow stretch's end before the widening
  // (steps from that end), or -1. `past_contact`: at the frame's edge, begin past the
  // stretch the edge cuts (EdgeContact).
  auto find_wrist = [&](int direction, bool past_contact, double within, double* wrist_width) {
    auto index = [&](int step) { return direction > 0 ? step : slices - 1 - step; };
    // Skip the end's cap, where the width still grows: a rounded end, or an arm that leaves
    // the frame obliquely, whose cut edge can rise unevenly, so there the cap lasts until
    // the width is near that of the stretch beyond it.
    const bool at_edge = (direction > 0 ? touch_low : touch_high) > 0;
    int first = 0;
    while (first + 1 < slices && width[index(first + 1)] > 1.02 * width[index(first)]) ++first;
    if (at_edge) {
      if (past_contact) first = std::max(first, static_cast<int>(std::ceil(direction > 0 ? contact.cap_low : contact.cap_high)));
      const int ahead = std::max(3, slices / 20);
      for (; first + ahead < slices; ++first) {
        std::vector<double> next;
        for (int j = first + 1; j <= first + ahead; ++j) next.push_back(width[index(j)]);
        std::nth_element(next.begin(), next.begin() + next.size() / 2, next.end());
        if (width[index(first)] >= 0.9 * next[next.size() / 2]) break;
      }
    }
    // The hand starts where the width first exceeds widen_ratio times the narrowest of the
    // last `within` narrowest widths' slices (infinite: all so far): their minimum kept by a
    // monotonic queue (steps of increasing width), the stretch's start only moving on as the
    // narrowest shrinks.
    double narrowest = 1e300;
    int hand_start = -1;
    std::deque<int> behind;
    for (int step = first; step < slices; ++step) {
      const double w = width[index(step)];
      if (step > first) {
        const int stretch_start =
            std::isinf(within) ? first : std::max(first, step - std::max(1, static_cast<int>(std::lround(within * narrowest))));
        while (behind.front() < stretch_start) behind.pop_front();
        if (w > options.widen_ratio * width[index(behind.front())]) {
          hand_start = step;
          break;
        }
      }
      while (!behind.empty() && width[index(behind.back())] >= w) behind.pop_back();
      behind.push_back(step);
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
  // The edge's stretch is skipped only where reading from the end finds no wrist: an arm
  // that leaves the frame at a slant widens along that stretch as a hand does, but the
  // stretch may also hold the wrist of a hand that meets the edge, or be a body's side (a
  // third of the region or more: no arm's end).
  auto from_end_within = [&](int direction, double within, double* w) {
    const int at = find_wrist(direction, false, within, w);
    const double cap = direction > 0 ? contact.cap_low : contact.cap_high;
    if (at >= 0 || cap < 1.0 || cap >= slices / 3.0) return at;
    return find_wrist(direction, true, within, w);
  };
  // The widening is judged against the narrowest so far first, and where that finds no arm
  // before it (an adult's arm widening towards its elbow), against the last stretch's.
  auto from_end = [&](int direction, double* w) {
    const int at = from_end_within(direction, std::numeric_limits<double>::infinity(), w);
    return at >= 0 ? at : from_end_within(direction, options.widen_within, w);
  };
  const int from_low = from_end(+1, &width_low);
  const int from_high = from_end(-1, &width_high);
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
  const std::vector<MaskRun> runs = Runs(result.hand);
  const Axis principal = AxisOf(runs);
  if (principal.pixels < 50) return result;
  const cv::Point2d axis(std::cos(principal.angle), std::sin(principal.angle));
  const Reading reading = Read(runs, principal.centre, axis, border, region.size(), options);
  if (reading.direction == 0) return result;
  const Frame f{reading.centre, reading.axis, cv::Point2d(-axis.y, axis.x)};
  for (const MaskRun& run : runs) {
    uint8_t* row = result.hand.ptr<uint8_t>(run.y);
    for (int x = run.x0; x <= run.x1; ++x) {
      if (OnArmSide(reading, f.T(x, run.y))) row[x] = 0;
    }
  }
  // The cut may leave crumbs of the arm's edge: of each piece the region had before the cut
  // (an object splits a held hand into several), keep the largest part.
  cv::Mat labels;
  const std::vector<RegionStats> parts = LabelRegions(result.hand, &labels);
  if (parts.size() > 2) {
    cv::Mat before;
    const std::vector<RegionStats> pieces = LabelRegions(region, &before);
    std::vector<int> largest(pieces.size(), 0);  // by piece: its largest part's label
    for (size_t l = 1; l < parts.size(); ++l) {
      int& best = largest[before.at<int>(parts[l].first)];
      if (best == 0 || parts[l].area > parts[best].area) best = static_cast<int>(l);
    }
    std::vector<uint8_t> keep(parts.size(), 0);
    for (int l : largest) {
      if (l > 0) keep[l] = 255;
    }
    for (int y = 0; y < labels.rows; ++y) {
      const int* in = labels.ptr<int>(y);
      uint8_t* out = result.hand.ptr<uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x) out[x] = keep[in[x]];
    }
  }
  result.cut = true;
  result.wrist_width = reading.wrist_width;
  result.wrist = reading.wrist;
  result.arm_direction = reading.direction > 0 ? -reading.axis : reading.axis;
  return result;
}

}  // namespace nphand

#include "nphand/eval/real_eval.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/progress.h"

namespace nphand {
namespace {

// Reads a still as 8-bit BGR; an image with transparency is laid on white, as a viewer
// shows it (a cut-out's hidden pixels are often black or arbitrary).
cv::Mat ReadStill(const std::filesystem::path& path) {
  const cv::Mat raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  NPHAND_THROW_CHECK(!raw.empty(), path.string(), ": cannot read this image");
  cv::Mat eight;
  if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else {
    eight = raw;
  }
  cv::Mat bgr;
  if (eight.channels() == 1) {
    cv::cvtColor(eight, bgr, cv::COLOR_GRAY2BGR);
  } else if (eight.channels() == 4) {
    bgr.create(eight.size(), CV_8UC3);
    for (int y = 0; y < eight.rows; ++y) {
      for (int x = 0; x < eight.cols; ++x) {
        const cv::Vec4b p = eight.at<cv::Vec4b>(y, x);
        const int a = p[3];
        for (int c = 0; c < 3; ++c) bgr.at<cv::Vec3b>(y, x)[c] = static_cast<uchar>((p[c] * a + 255 * (255 - a) + 127) / 255);
      }
    }
  } else {
    bgr = eight;
  }
  return bgr;
}

PredictedHand HandOf(const FrameResult& result) {
  PredictedHand hand;
  hand.keypoints_2d = result.keypoints_2d;
  hand.keypoints_3d = result.keypoints_hand;
  hand.hand = ToString(result.hand);
  return hand;
}

// The estimate of `estimator` into `prediction`: its hand, or why it found none.
void Record(const Estimator& estimator, const FrameResult& result, RealPrediction* prediction) {
  if (result.detected()) {
    prediction->hands.push_back(HandOf(result));
    return;
  }
  const EstimatorOptions& options = estimator.options();
  prediction->missed.push_back({options.hand_auto ? "" : ToString(options.hand), ToString(result.status), result.reason});
}

// What the estimator sees of a frame: the frame shrunk (area averaging) until its longer
// side is at most `max_side` pixels (0: as it is).
cv::Mat Shrunk(const cv::Mat& bgr, int max_side) {
  const int side = std::max(bgr.cols, bgr.rows);
  if (max_side == 0 || side <= max_side) return bgr;
  const double scale = static_cast<double>(max_side) / side;
  const cv::Size size(std::max(1, static_cast<int>(std::lround(bgr.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(bgr.rows * scale))));
  cv::Mat seen;
  cv::resize(bgr, seen, size, 0.0, 0.0, cv::INTER_AREA);
  return seen;
}

// The estimate on `seen` (the frame of size `frame` shrunk), its 2D keypoints mapped back
// to the frame's pixels; `roi` is in the frame's pixels. Only the 2D keypoints are mapped
// (all that is scored): the box, the camera-frame keypoints and the depth stay the shrunk
// frame's.
FrameResult ProcessShrunk(Estimator* estimator, const cv::Mat& seen, cv::Size frame, double time_s,
                          const std::optional<cv::Rect>& roi) {
  const double sx = static_cast<double>(seen.cols) / frame.width, sy = static_cast<double>(seen.rows) / frame.height;
  std::optional<cv::Rect> seen_roi;
  if (roi.has_value()) {
    const int x0 = static_cast<int>(std::floor(roi->x * sx)), y0 = static_cast<int>(std::floor(roi->y * sy));
    const int x1 = static_cast<int>(std::ceil((roi->x + roi->width) * sx));
    const int y1 = static_cast<int>(std::ceil((roi->y + roi->height) * sy));
    seen_roi = cv::Rect(x0, y0, x1 - x0, y1 - y0);
  }
  FrameResult result = estimator->Process(seen, time_s, seen_roi);
  if (result.detected()) {
    for (Eigen::Vector2d& k : result.keypoints_2d) k = Eigen::Vector2d(k.x() / sx, k.y() / sy);
  }
  return result;
}

}  // namespace

bool RealRunOptions::Check(std::string* why) const {
  if (max_side != 0 && max_side < 16) {
    *why = "--max-side (the frames' longer side) is 0 (as they are) or at least 16 pixels, not " + std::to_string(max_side);
    return false;
  }
  return true;
}

void CheckRealFiles(const std::vector<RealLabel>& labels, const std::filesystem::path& root) {
  std::set<std::string> checked;
  for (const RealLabel& label : labels) {
    if (!checked.insert(label.file).second) continue;
    const std::filesystem::path path = root / label.file;
    std::error_code ec;
    NPHAND_THROW_CHECK(std::filesystem::is_regular_file(path, ec), "labels line ", label.line + 1, ": ", path.string(),
                       ": no such file");
    if (label.frame.has_value()) {
      cv::VideoCapture video(path.string(), cv::CAP_FFMPEG);
      NPHAND_THROW_CHECK(video.isOpened(), path.string(), ": cannot read this as a video");
    } else {
      NPHAND_THROW_CHECK(cv::haveImageReader(path.string()), path.string(), ": not an image OpenCV can read");
    }
  }
}

std::vector<RealPrediction> EstimateReal(const std::vector<RealLabel>& labels, const std::filesystem::path& root,
                                         Estimator* right, Estimator* left, const RealRunOptions& run, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(run.Check(&why), "eval real: ", why);
  // Images and videos in the order of their first label; the sides labelled in each, and
  // the labels of each still and of each video frame.
  std::vector<std::string> stills, videos;
  std::map<std::string, std::set<std::string>> sides;
  std::map<std::string, std::set<int>> frames;
  std::map<std::string, std::vector<const RealLabel*>> of_still;
  std::map<std::pair<std::string, int>, const RealLabel*> of_frame;
  for (const RealLabel& label : labels) {
    std::vector<std::string>& list = label.frame.has_value() ? videos : stills;
    if (std::find(list.begin(), list.end(), label.file) == list.end()) list.push_back(label.file);
    sides[label.file].insert(label.hand.empty() ? "right" : label.hand);
    if (label.frame.has_value()) {
      frames[label.file].insert(*label.frame);
      of_frame.emplace(std::make_pair(label.file, *label.frame), &label);
    } else {
      of_still[label.file].push_back(&label);
    }
  }
  // A label's found region, whole pixels around it.
  auto region_of = [](const RealLabel& label) {
    const int x0 = static_cast<int>(std::floor(label.region[0])), y0 = static_cast<int>(std::floor(label.region[1]));
    return cv::Rect(x0, y0, static_cast<int>(std::ceil(label.region[2])) - x0, static_cast<int>(std::ceil(label.region[3])) - y0);
  };
  auto estimator_of = [&](const std::string& side) { return left != nullptr && side == "left" ? left : right; };
  uint64_t total = stills.size();
  for (const std::string& video : videos) total += static_cast<uint64_t>(*frames[video].rbegin() + 1);
  ProgressLine line(progress, "eval real", total, "images");
  uint64_t done = 0;
  std::vector<RealPrediction> predictions;
  for (const std::string& file : stills) {
    const cv::Mat bgr = ReadStill(root / file);
    const cv::Mat seen = Shrunk(bgr, run.max_side);
    RealPrediction prediction;
    prediction.file = file;
    prediction.ms = 0.0;
    // One estimate a labelled side, or one in all when the estimator chooses the side; with
    // the place given, one a labelled hand, within its region.
    std::vector<std::pair<Estimator*, std::optional<cv::Rect>>> estimates;
    if (run.given_box) {
      for (const RealLabel* label : of_still[file]) estimates.emplace_back(estimator_of(label->hand), region_of(*label));
    } else if (left != nullptr) {
      for (const std::string& side : sides[file]) estimates.emplace_back(estimator_of(side), std::nullopt);
    } else {
      estimates.emplace_back(right, std::nullopt);
    }
    for (const auto& [estimator, roi] : estimates) {
      estimator->Reset();
      const FrameResult result = ProcessShrunk(estimator, seen, bgr.size(), 0.0, roi);
      *prediction.ms += result.ms.total;
      Record(*estimator, result, &prediction);
    }
    predictions.push_back(std::move(prediction));
    line.Update(++done);
  }
  for (const std::string& file : videos) {
    // One side per video: the first labelled.
    Estimator* estimator = estimator_of(*sides[file].begin());
    estimator->Reset();
    cv::VideoCapture video((root / file).string(), cv::CAP_FFMPEG);
    NPHAND_THROW_CHECK(video.isOpened(), (root / file).string(), ": cannot read this as a video");
    const double fps = video.get(cv::CAP_PROP_FPS) > 0.0 ? video.get(cv::CAP_PROP_FPS) : 25.0;
    const int last = *frames[file].rbegin();
    cv::Mat bgr;
    for (int frame = 0; frame <= last; ++frame) {
      NPHAND_THROW_CHECK(video.read(bgr) && !bgr.empty(), (root / file).string(), ": ends at frame ", frame,
                         ", but frames up to ", last, " are labelled");
      std::optional<cv::Rect> roi;
      if (const auto it = of_frame.find({file, frame}); run.given_box && it != of_frame.end()) roi = region_of(*it->second);
      const FrameResult result = ProcessShrunk(estimator, Shrunk(bgr, run.max_side), bgr.size(), frame / fps, roi);
      if (frames[file].count(frame)) {
        RealPrediction prediction;
        prediction.file = file;
        prediction.frame = frame;
        prediction.ms = result.ms.total;
        Record(*estimator, result, &prediction);
        predictions.push_back(std::move(prediction));
      }
      line.Update(++done);
    }
  }
  line.Finish();
  return predictions;
}

cv::Mat RealContactSheet(const std::vector<RealLabel>& labels, const std::vector<RealPrediction>& predictions,
                         const RealScore& score, const std::filesystem::path& root) {
  constexpr int kTile = 240, kCaption = 18, kColumns = 8;
  std::vector<std::string> stills;
  for (const RealLabel& label : labels) {
    if (!label.frame.has_value() && std::find(stills.begin(), stills.end(), label.file) == stills.end()) stills.push_back(label.file);
  }
  const int rows = (static_cast<int>(stills.size()) + kColumns - 1) / kColumns;
  cv::Mat sheet(std::max(1, rows) * (kTile + kCaption), kColumns * kTile, CV_8UC3, cv::Scalar(24, 24, 24));
  for (size_t i = 0; i < stills.size(); ++i) {
    const std::string& file = stills[i];
    double scale = 1.0;
    cv::Point offset;
    cv::Mat tile = FitInto(ReadStill(root / file), cv::Size(kTile, kTile), cv::Scalar(24, 24, 24), &scale, &offset);
    const auto place = [&](const Eigen::Vector2d& p) { return Eigen::Vector2d(p.x() * scale + offset.x, p.y() * scale + offset.y); };
    int found = 0, hands = 0;
    for (const RealHandScore& r : score.hands) {
      if (r.label->file != file || r.label->frame.has_value()) continue;
      ++hands;
      found += r.found;
      const cv::Scalar green(80, 220, 80);
      if (r.label->labelled.empty()) {
        const Eigen::Vector2d a = place({r.label->box[0], r.label->box[1]}), b = place({r.label->box[2], r.label->box[3]});
        cv::rectangle(tile, cv::Point(int(a.x()), int(a.y())), cv::Point(int(b.x()), int(b.y())), green, 1);
      }
      for (int k : r.label->labelled) {
        const Eigen::Vector2d p = place(*r.label->keypoints_2d[k]);
        cv::circle(tile, cv::Point(int(p.x()), int(p.y())), 3, green, 1, cv::LINE_AA);
      }
    }
    for (const RealPrediction& p : predictions) {
      if (p.file != file || p.frame.has_value()) continue;
      for (const PredictedHand& hand : p.hands) {
        std::array<Eigen::Vector2d, kNumKeypoints> placed;
        for (int k = 0; k < kNumKeypoints; ++k) placed[k] = place(hand.keypoints_2d[k]);
        DrawKeypoints2d(placed, &tile);
      }
    }
    const int x = static_cast<int>(i % kColumns) * kTile, y = static_cast<int>(i / kColumns) * (kTile + kCaption);
    tile.copyTo(sheet(cv::Rect(x, y, kTile, kTile)));
    const std::string caption = std::filesystem::path(file).stem().string().substr(0, 22) + " " + std::to_string(found) + "/" +
                                std::to_string(hands);
    cv::putText(sheet, caption, cv::Point(x + 4, y + kTile + 13), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                found == hands ? cv::Scalar(200, 255, 200) : cv::Scalar(120, 120, 255), 1, cv::LINE_AA);
  }
  return sheet;
}

}  // namespace nphand

#include "apps/estimate_command.h"

#include <chrono>
#include <cstdio>
#include <fstream>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "apps/frame_source.h"
#include "nphand/estimate/frame_json.h"
#include "nphand/index/backends.h"
#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/progress.h"

namespace nphand {
namespace {

// The frame with the skeleton and box, and beside it the matched database view (with its
// object) and what was found.
cv::Mat Overlay(const cv::Mat& frame, const FrameResult& result, Estimator* estimator, const Database& db) {
  cv::Mat left = frame.clone();
  const int side = frame.rows / 2;
  cv::Mat panel(frame.rows, side, CV_8UC3, cv::Scalar(32, 32, 32));
  const double scale = std::max(0.4, frame.rows / 960.0);
  auto text = [&](cv::Mat* image, const std::string& s, int line, cv::Scalar colour) {
    cv::putText(*image, s, cv::Point(8, side + static_cast<int>((line + 1) * 24 * scale)), cv::FONT_HERSHEY_SIMPLEX,
                0.5 * scale, colour, 1, cv::LINE_AA);
  };
  if (result.detected()) {
    cv::rectangle(left, result.box, cv::Scalar(255, 255, 255), 1);
    DrawKeypoints2d(result.keypoints_2d, &left);
    cv::Mat view = estimator->RenderEntry(result.top[0].entry).rgb;
    cv::resize(view, panel(cv::Rect(0, 0, side, side)), cv::Size(side, side), 0, 0, cv::INTER_NEAREST);
    const EntryMeta meta = db.Meta(result.top[0].entry);
    char line[128];
    std::snprintf(line, sizeof(line), "%s p=%.2f", result.grasps[0].first.c_str(), result.grasps[0].second);
    text(&panel, line, 0, cv::Scalar(255, 255, 255));
    std::snprintf(line, sizeof(line), "object %s p=%.2f", result.objects[0].first.c_str(), result.objects[0].second);
    text(&panel, line, 1, cv::Scalar(255, 255, 255));
    std::snprintf(line, sizeof(line), "entry %u step %d conf %.2f", result.top[0].entry, meta.step, result.confidence);
    text(&panel, line, 2, cv::Scalar(200, 200, 200));
    std::snprintf(line, sizeof(line), "%.2f m, %.1f ms", result.depth_m, result.ms.total);
    text(&panel, line, 3, cv::Scalar(200, 200, 200));
  } else {
    text(&panel, "no hand: " + ToString(result.status), 0, cv::Scalar(80, 80, 255));
  }
  cv::Mat out;
  cv::hconcat(left, panel, out);
  return out;
}

}  // namespace

nlohmann::json RunEstimate(const EstimateCommandOptions& options, std::ostream* progress, const std::atomic<bool>* stop) {
  EstimatorOptions estimator_options = options.estimator;
  estimator_options.hand = HandednessFromString(options.hand);
  estimator_options.observation = ObservationWeightFromString(options.observation);
  estimator_options.prior = PriorCombinationFromString(options.prior);
  if (!options.faces) estimator_options.skin.face_cascade.clear();
  std::string why;
  NPHAND_THROW_CHECK(estimator_options.Check(&why), "estimate: ", why);
  CheckOutputFile(options.out, "--out");
  if (!options.overlay.empty()) CheckOutputFile(options.overlay, "--overlay");
  const std::filesystem::path index_path = options.index.empty() ? std::filesystem::path(options.db.string() + ".idx") : options.index;
  std::error_code error;
  NPHAND_THROW_CHECK(std::filesystem::exists(options.db, error), options.db.string(),
                     ": no database there (make one with `nphand db build`)");
  NPHAND_THROW_CHECK(std::filesystem::exists(index_path, error), index_path.string(),
                     ": no index there (make one with `nphand index build --db ", options.db.string(), "`)");
  FrameSource source(options.input, options.fps);

  const Database db = Database::Open(options.db);
  const std::unique_ptr<KnnIndex> index = LoadIndex(index_path, db);
  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  Estimator estimator(db, *index, hand, estimator_options);

  // Lines go to a partial file as they come; a stop or an error still leaves whole lines,
  // and the finished file takes the final name.
  const std::filesystem::path partial = options.out.string() + ".partial";
  std::ofstream out(partial, std::ios::binary | std::ios::trunc);
  NPHAND_THROW_CHECK(out.good(), partial.string(), ": cannot write");
  cv::VideoWriter video;
  const std::filesystem::path video_partial = options.overlay.string() + ".partial.mp4";

  const uint64_t total = options.max_frames > 0 && source.count() > 0 ? std::min(options.max_frames, source.count())
                         : options.max_frames > 0                      ? options.max_frames
                                                                       : source.count();
  ProgressLine line(progress, "estimate", total, "frames");
  uint64_t frames = 0, detected = 0;
  double estimate_ms = 0.0;
  bool stopped = false;
  const auto start = std::chrono::steady_clock::now();
  while (options.max_frames == 0 || frames < options.max_frames) {
    if (stop != nullptr && stop->load()) {
      stopped = true;
      break;
    }
    std::optional<Frame> frame = source.Next();
    if (!frame.has_value()) break;
    const FrameResult result = estimator.Process(frame->bgr, frame->time_s);
    nlohmann::json json = FrameResultJson(result, db, options.top);
    if (!frame->name.empty()) json["image"] = frame->name;
    out << json.dump() << '\n';
    out.flush();
    NPHAND_THROW_CHECK(out.good(), partial.string(), ": write failed (disk full?)");
    if (!options.overlay.empty()) {
      const cv::Mat picture = Overlay(frame->bgr, result, &estimator, db);
      if (!video.isOpened()) {
        video.open(video_partial.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), source.fps(), picture.size());
        NPHAND_THROW_CHECK(video.isOpened(), video_partial.string(), ": cannot open a video writer (MPEG-4)");
      }
      video.write(picture);
    }
    ++frames;
    detected += result.detected();
    estimate_ms += result.ms.total;
    if (total > 0) line.Update(std::min(frames, total));
  }
  line.Finish();
  out.close();
  std::filesystem::rename(partial, options.out);
  if (video.isOpened()) {
    video.release();
    std::filesystem::rename(video_partial, options.overlay);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json summary = {{"input", options.input},
                            {"input_kind", source.kind()},
                            {"frames", frames},
                            {"detected", detected},
                            {"stopped", stopped},
                            {"seconds", seconds},
                            {"estimate_ms_mean", frames > 0 ? estimate_ms / frames : 0.0},
                            {"out", options.out.string()}};
  if (!options.overlay.empty() && frames > 0) summary["overlay"] = options.overlay.string();
  return summary;
}

}  // namespace nphand

#include "apps/estimate_command.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "apps/frame_source.h"
#include "apps/index_command.h"
#include "apps/video_file.h"
#include "nphand/estimate/frame_json.h"
#include "nphand/index/backends.h"
#include "nphand/motion/bvh.h"
#include "nphand/motion/gltf_motion.h"
#include "nphand/motion/motion.h"
#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/io.h"
#include "nphand/util/progress.h"
#include "nphand/util/text.h"

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

// The overlay's frame for an image that could not be read: grey, with why.
cv::Mat UnreadablePicture(cv::Size size, const std::string& reason) {
  cv::Mat picture(size, CV_8UC3, cv::Scalar(64, 64, 64));
  cv::putText(picture, "unreadable: " + reason.substr(0, 60), cv::Point(8, size.height / 2), cv::FONT_HERSHEY_SIMPLEX,
              std::max(0.4, size.height / 960.0) * 0.5, cv::Scalar(80, 80, 255), 1, cv::LINE_AA);
  return picture;
}

// Every file a run reads: refused as an output.
std::vector<NamedPath> Inputs(const EstimateCommandOptions& options, const FrameSource& source) {
  std::vector<NamedPath> inputs = options.Inputs();
  inputs.push_back({options.asset_dir / "right.glb", "the hand asset"});
  inputs.push_back({options.asset_dir / "left.glb", "the hand asset"});
  if (source.kind() == "video") inputs.push_back({options.input, "--input"});
  for (const std::filesystem::path& image : source.images()) inputs.push_back({image, "an image of --input"});
  if (options.faces) inputs.push_back({options.estimator.skin.face_cascade, "the face cascade"});
  return inputs;
}

// The motion files of a run: every frame's estimate kept once, the side found in more
// frames written as the track.
class MotionOutputs {
 public:
  MotionOutputs(const EstimateCommandOptions& options, double fps, double scale)
      : options_(options), fps_(fps), scale_(scale) {}
  bool wanted() const { return !options_.bvh.empty() || !options_.gltf.empty(); }

  void Add(const FrameResult* result) {
    if (!wanted()) return;
    std::optional<MotionFrame> frame;
    if (result != nullptr && result->detected()) {
      frame = MotionFrame{result->pose, result->keypoints_camera[0]};
      ++(result->pose.handedness == Handedness::kLeft ? lefts_ : rights_);
    }
    frames_.push_back(std::move(frame));
  }

  // Writes the files (atomically); throws nphand::Error when no frame had a hand.
  void Write(nlohmann::json* summary) const {
    MotionRecorder track(lefts_ > rights_ ? Handedness::kLeft : Handedness::kRight, fps_, scale_);
    for (const std::optional<MotionFrame>& frame : frames_) track.Add(frame);
    const Motion motion = track.Finish();
    const HandModel hand = HandModel::Load(motion.hand, options_.asset_dir);
    if (!options_.bvh.empty()) {
      WriteBvh(hand, motion, options_.bvh);
      (*summary)["bvh"] = Utf8OrEscaped(options_.bvh.string());
    }
    if (!options_.gltf.empty()) {
      WriteGltfMotion(hand, ReadFileBytes(options_.asset_dir / AssetFileName(motion.hand)), motion, options_.gltf);
      (*summary)["gltf"] = Utf8OrEscaped(options_.gltf.string());
    }
    (*summary)["motion"] = {{"hand", ToString(motion.hand)}, {"frames", motion.frames.size()},
                            {"with_hand", track.with_hand()}, {"scale", motion.scale}};
  }

 private:
  const EstimateCommandOptions& options_;
  double fps_, scale_;
  std::vector<std::optional<MotionFrame>> frames_;
  size_t lefts_ = 0, rights_ = 0;
};

}  // namespace

const char* SignalName(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

nlohmann::json RunEstimate(const EstimateCommandOptions& options, std::ostream* progress, const std::atomic<int>* stop) {
  EstimatorOptions estimator_options = options.estimator;
  SetHandChoice(options.hand, &estimator_options);
  estimator_options.observation = ObservationWeightFromString(options.observation);
  estimator_options.prior = PriorCombinationFromString(options.prior);
  SetRefineMoves(options.refine_move, &estimator_options.refinement);
  if (!options.faces) estimator_options.skin.face_cascade.clear();
  std::string why;
  NPHAND_THROW_CHECK(estimator_options.Check(&why), "estimate: ", why);
  NPHAND_THROW_CHECK(options.roi.empty() || (options.roi.size() == 4 && options.roi[2] > 0 && options.roi[3] > 0),
                     "estimate: --roi is x,y,width,height in pixels, with a width and height above 0");
  std::optional<cv::Rect> roi;
  if (!options.roi.empty()) roi = cv::Rect(options.roi[0], options.roi[1], options.roi[2], options.roi[3]);
  CheckOutputFile(options.out, "--out");
  if (!options.overlay.empty()) CheckOutputFile(options.overlay, "--overlay");
  if (!options.bvh.empty()) CheckOutputFile(options.bvh, "--bvh");
  if (!options.gltf.empty()) CheckOutputFile(options.gltf, "--gltf");
  FrameSource source(options.input, options.fps);
  std::vector<NamedPath> outputs = {{options.out, "--out"}};
  if (!options.overlay.empty()) outputs.push_back({options.overlay, "--overlay"});
  if (!options.bvh.empty()) outputs.push_back({options.bvh, "--bvh"});
  if (!options.gltf.empty()) outputs.push_back({options.gltf, "--gltf"});
  // A clash first: it is the graver mistake, and names the file at stake.
  CheckOutputsApart(Inputs(options, source), outputs);
  options.CheckPresent();
  if (!options.overlay.empty()) {
    NPHAND_THROW_CHECK(AsciiLower(options.overlay.extension().string()) == ".mp4", "--overlay '", options.overlay.string(),
                       "': nphand writes the overlay as MPEG-4; name it .mp4");
  }
  NPHAND_THROW_CHECK(options.bvh.empty() || AsciiLower(options.bvh.extension().string()) == ".bvh", "--bvh '",
                     options.bvh.string(), "': name the motion file .bvh");
  NPHAND_THROW_CHECK(options.gltf.empty() || AsciiLower(options.gltf.extension().string()) == ".glb", "--gltf '",
                     options.gltf.string(), "': nphand writes binary glTF; name it .glb");

  // The outputs are taken (locked) before the long load, so that a second run into them is
  // refused at once; their final names are replaced only when the run has frames to show.
  LineFile lines(options.out);
  std::optional<VideoFile> overlay;
  if (!options.overlay.empty()) overlay.emplace(options.overlay, source.fps());

  const OpenedFiles files(options);
  const Database& db = files.db;
  Estimator estimator(db, *files.index, files.hand, estimator_options);
  MotionOutputs motion(options, source.fps(), estimator_options.hand_length_m / ModelHandLength(db));

  const uint64_t total = options.max_frames > 0 && source.count() > 0 ? std::min(options.max_frames, source.count())
                         : options.max_frames > 0                      ? options.max_frames
                                                                       : source.count();
  ProgressLine line(progress, "estimate", total, "frames");
  uint64_t frames = 0, detected = 0, unreadable = 0, damaged = 0;
  double estimate_ms = 0.0;
  int signal = 0;
  bool input_ended = false;
  std::vector<std::string> unreadable_reasons;  // of frames before the overlay's size is known
  const auto start = std::chrono::steady_clock::now();
  try {
    while (options.max_frames == 0 || frames < options.max_frames) {
      if (stop != nullptr && (signal = stop->load()) != 0) break;
      std::optional<Frame> frame = source.Next();
      if (!frame.has_value()) {
        input_ended = true;
        break;
      }
      nlohmann::json json;
      if (!frame->error.empty()) {
        json = {{"frame", frames}, {"time_s", frame->time_s}, {"detected", false}, {"status", "unreadable"},
                {"reason", frame->error}};
        ++unreadable;
        motion.Add(nullptr);
        if (overlay.has_value() && overlay->frames() > 0) {
          overlay->Write(UnreadablePicture(overlay->size(), frame->error));
        } else if (overlay.has_value()) {
          unreadable_reasons.push_back(frame->error);
        }
      } else {
        const FrameResult result = estimator.Process(frame->bgr, frame->time_s, roi);
        json = FrameResultJson(result, db, options.top);
        json["frame"] = frames;  // the input's numbering, unreadable frames included
        detected += result.detected();
        estimate_ms += result.ms.total;
        motion.Add(&result);
        if (overlay.has_value()) {
          const cv::Mat picture = Overlay(frame->bgr, result, &estimator, db);
          overlay->Size(picture.size());
          for (const std::string& reason : unreadable_reasons) overlay->Write(UnreadablePicture(overlay->size(), reason));
          unreadable_reasons.clear();
          overlay->Write(picture);
        }
      }
      if (!frame->name.empty()) json["image"] = frame->name;
      if (!frame->warnings.empty()) {
        json["warnings"] = frame->warnings;
        ++damaged;
      }
      lines.Write(json.dump());
      ++frames;
      if (total > 0) line.Update(std::min(frames, total));
    }
    line.Finish();
    if (frames > 0) {
      // The poses first: a damaged overlay must not cost them.
      lines.Commit();
      if (overlay.has_value() && overlay->frames() > 0) overlay->Finish();
    }
  } catch (const Error& e) {
    if (frames == 0) throw;
    if (lines.committed()) throw Error(std::string(e.what()) + " (the poses are complete in " + options.out.string() + ")");
    lines.Keep();
    throw Error(std::string(e.what()) + " (the " + std::to_string(lines.lines()) + " whole lines written are in " +
                lines.partial().string() + ")");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json motion_files = nlohmann::json::object();
  if (frames > 0 && motion.wanted()) {
    try {
      motion.Write(&motion_files);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (the poses are complete in " + options.out.string() + ")");
    }
  }
  nlohmann::json summary = {{"input", Utf8OrEscaped(options.input)},
                            {"input_kind", source.kind()},
                            {"frames", frames},
                            {"detected", detected},
                            {"unreadable", unreadable},
                            {"damaged", damaged},
                            {"stopped", signal != 0},
                            {"seconds", seconds},
                            {"estimate_ms_mean", frames - unreadable > 0 ? estimate_ms / (frames - unreadable) : 0.0}};
  if (signal != 0) summary["signal"] = SignalName(signal);
  // A video that ends before the frames its container promised was cut short.
  const bool truncated = input_ended && source.kind() == "video" && source.count() > source.read();
  summary["input_complete"] = !truncated;
  if (source.count() > 0) summary["frames_expected"] = source.count();
  if (truncated && progress != nullptr) {
    *progress << "estimate: warning: " << Utf8OrEscaped(options.input) << " ended after " << source.read()
              << " frames, but its container promised " << source.count() << ": the video is truncated or damaged\n";
  }
  if (frames > 0) {
    summary["out"] = Utf8OrEscaped(options.out.string());
    if (overlay.has_value() && overlay->frames() > 0) summary["overlay"] = Utf8OrEscaped(options.overlay.string());
    summary.update(motion_files);
  } else {
    summary["out"] = nullptr;
  }
  return summary;
}

}  // namespace nphand

#include "apps/sequence_command.h"

#include <cstdio>

#include <opencv2/videoio.hpp>

#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/io.h"
#include "nphand/util/progress.h"

namespace nphand {

nlohmann::json RunSequence(const SequenceCommandOptions& options, std::ostream* progress) {
  SequenceOptions sequence_options = options.sequence;
  sequence_options.forearm = ForearmKindFromString(options.forearm);
  sequence_options.background = BackgroundKindFromString(options.background);
  sequence_options.hand = HandednessFromString(options.hand);
  std::string why;
  NPHAND_THROW_CHECK(sequence_options.Check(&why), "sequence: ", why);
  CheckOutputFolder(options.out_dir, "--out");
  CheckOutputFolder(options.out_dir / "frames", "--out");
  CheckOutputFolder(options.out_dir / "labels", "--out");

  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  Sequence sequence(hand, sequence_options);
  nlohmann::json description = sequence.Describe();
  description["files"] = {{"frames", "frames/%06d.png"}, {"labels", "labels/%06d.png"}, {"truth", "truth.jsonl"}};

  cv::VideoWriter video;
  const std::filesystem::path video_partial = options.out_dir / "video.mp4.partial.mp4";
  if (options.video) {
    video.open(video_partial.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), sequence_options.fps,
               cv::Size(sequence_options.width, sequence_options.height));
    NPHAND_THROW_CHECK(video.isOpened(), video_partial.string(), ": cannot open a video writer (MPEG-4)");
    description["files"]["video"] = "video.mp4";
  }
  std::string truth;
  ProgressLine line(progress, "sequence", static_cast<uint64_t>(sequence.size()), "frames");
  for (int i = 0; i < sequence.size(); ++i) {
    const SequenceFrame frame = sequence.Render(i);
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    WriteImageAtomic(options.out_dir / "frames" / name, frame.rgb);
    WriteImageAtomic(options.out_dir / "labels" / name, frame.labels);
    truth += FrameTruthJson(frame).dump() + "\n";
    if (video.isOpened()) video.write(frame.rgb);
    line.Update(static_cast<uint64_t>(i + 1));
  }
  line.Finish();
  if (video.isOpened()) {
    video.release();
    std::filesystem::rename(video_partial, options.out_dir / "video.mp4");
  }
  WriteFileAtomic(options.out_dir / "truth.jsonl", truth);
  WriteFileAtomic(options.out_dir / "sequence.json", description.dump(2) + "\n");
  return description;
}

}  // namespace nphand

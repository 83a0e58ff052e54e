#include "apps/sequence_command.h"

#include <cstdio>
#include <optional>

#include "apps/video_file.h"
#include "nphand/render/draw.h"
#include "nphand/scene/gesture.h"
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
  if (!options.gesture.empty()) {
    NPHAND_THROW_CHECK(sequence_options.grasp == 0, "sequence: --grasp and --gesture exclude each other");
    sequence_options.grasp = GestureByName(options.gesture).id;
    sequence_options.object = false;
  }
  std::string why;
  NPHAND_THROW_CHECK(sequence_options.Check(&why), "sequence: ", why);
  CheckOutputFolder(options.out_dir, "--out");
  CheckOutputFolder(options.out_dir / "frames", "--out");
  CheckOutputFolder(options.out_dir / "labels", "--out");

  NPHAND_THROW_CHECK(options.proportions.size() == 2, "sequence: --proportions takes two factors, length and width");
  const HandModel hand =
      HandModel::Load(Handedness::kRight, options.asset_dir).Reproportioned(options.proportions[0], options.proportions[1]);
  Sequence sequence(hand, sequence_options);
  nlohmann::json description = sequence.Describe();
  description["hand_proportions"] = {{"length", options.proportions[0]}, {"width", options.proportions[1]}};
  description["files"] = {{"frames", "frames/%06d.png"}, {"labels", "labels/%06d.png"}, {"truth", "truth.jsonl"}};

  std::optional<VideoFile> video;
  if (options.video) {
    video.emplace(options.out_dir / "video.mp4", sequence_options.fps);
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
    if (video.has_value()) video->Write(frame.rgb);
    line.Update(static_cast<uint64_t>(i + 1));
  }
  line.Finish();
  if (video.has_value()) video->Finish();
  WriteFileAtomic(options.out_dir / "truth.jsonl", truth);
  WriteFileAtomic(options.out_dir / "sequence.json", description.dump(2) + "\n");
  return description;
}

}  // namespace nphand

// A user's program against the installed package: builds a tiny database and its index,
// renders one frame of a sequence and estimates the hand's pose on it. The hand mesh comes
// from the install's share folder (or $NPHAND_ASSET_DIR). Prints one line per step; exits
// non-zero when a step fails.
#include <filesystem>
#include <iostream>
#include <memory>

#include <nphand/db/builder.h>
#include <nphand/db/database.h>
#include <nphand/estimate/estimator.h>
#include <nphand/index/backends.h>
#include <nphand/model/hand_model.h>
#include <nphand/sequence/sequence.h>
#include <nphand/util/check.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: consumer <scratch folder>\n";
    return 2;
  }
  try {
    const std::filesystem::path scratch = argv[1];
    std::filesystem::create_directories(scratch);
    const nphand::HandModel hand = nphand::HandModel::Load(nphand::Handedness::kRight);
    std::cout << "hand mesh from " << nphand::DefaultAssetDir().string() << ": " << hand.bind_vertices().size()
              << " vertices\n";

    nphand::DatabaseBuildOptions build;
    build.grasps = {1};
    build.gestures = {};
    build.directions = 24;
    build.image_size = 96;
    build.threads = 1;
    const std::filesystem::path path = scratch / "tiny.db";
    nphand::BuildDatabase(hand, build, path, nullptr);
    const nphand::Database db = nphand::Database::Open(path);
    std::cout << "database: " << db.size() << " entries\n";
    const std::unique_ptr<nphand::KnnIndex> index = nphand::BuildIndex(db, nphand::IndexOptions::Exact());

    nphand::SequenceOptions sequence_options;
    sequence_options.frames = 2;
    sequence_options.grasp = 1;
    sequence_options.object_scale = 1.0;
    sequence_options.background = nphand::BackgroundKind::kPlain;
    sequence_options.seed = 3;
    nphand::Sequence sequence(hand, sequence_options);
    const nphand::SequenceFrame frame = sequence.Render(0);

    nphand::Estimator estimator(db, *index, hand, nphand::EstimatorOptions{});
    const nphand::FrameResult result = estimator.Process(frame.rgb, frame.time_s);
    if (!result.detected()) {
      std::cerr << "consumer: no hand found: " << result.reason << "\n";
      return 1;
    }
    // A 240-entry database places the hand, not its fine pose: check where it was found.
    const Eigen::Vector2d truth = frame.keypoints_2d[9];
    const bool in_box = result.box.contains(cv::Point(static_cast<int>(truth.x()), static_cast<int>(truth.y())));
    std::cout << "estimated frame 0: hand box " << result.box.width << "x" << result.box.height << " at ("
              << result.box.x << ", " << result.box.y << "), the true middle knuckle "
              << (in_box ? "inside" : "OUTSIDE") << " it; wrist rotation "
              << nphand::RotationAngleDeg(result.pose.camera_from_hand, frame.pose.camera_from_hand)
              << " degrees from the truth\n";
    return in_box ? 0 : 1;
  } catch (const nphand::Error& e) {
    std::cerr << "consumer: " << e.what() << "\n";
    return 1;
  }
}

// `nphand sequence`: renders a grasping sequence with ground truth into a folder:
// frames/NNNNNN.png (the camera's view), labels/NNNNNN.png (PixelLabel values), truth.jsonl
// (one JSON object per frame, docs/FORMAT.md), sequence.json (what was rendered) and, if
// asked, video.mp4. Its frames folder is an input of `nphand estimate`.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/model/hand_model.h"
#include "nphand/sequence/sequence.h"

namespace nphand {

struct SequenceCommandOptions {
  SequenceOptions sequence;
  std::string gesture;                   // a gesture's name: the hand shape instead of sequence.grasp, no object
  std::string forearm = "bare";          // none | bare | sleeved
  std::string background = "texture";   // plain | texture | clutter
  std::string hand = "right";
  // The hand's length and width as factors of the database hand's (HandModel::Reproportioned):
  // a hand unlike the one the database was rendered from.
  std::vector<double> proportions = {1.0, 1.0};
  bool video = false;                    // also write video.mp4 (MPEG-4 part 2)
  std::filesystem::path out_dir = "out/sequence";
  std::filesystem::path asset_dir = DefaultAssetDir();
};

// Writes the sequence; returns sequence.json's content. Progress goes to `progress`.
nlohmann::json RunSequence(const SequenceCommandOptions& options, std::ostream* progress);

}  // namespace nphand

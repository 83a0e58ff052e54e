// What the estimate command's test suites share: a fresh folder holding the tiny database
// with an exact index (tiny.db, tiny.db.idx) and a short rendered sequence with its video
// (sequence/: frames, truth.jsonl, video.mp4).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include "apps/index_command.h"
#include "apps/sequence_command.h"
#include "testing/tiny_db.h"

namespace nphand::testing {

// Makes the folder temp/<name>_<pid> with the database and a `frames`-frame sequence.
inline std::filesystem::path MakeCommandFixture(const std::string& name, int frames) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  BuildTinyDatabase(dir / "tiny.db");
  IndexBuildCommandOptions index;
  index.db = dir / "tiny.db";
  index.index = IndexOptions::Exact();
  RunIndexBuild(index);
  SequenceCommandOptions sequence;
  sequence.sequence.frames = frames;
  sequence.sequence.width = 240;
  sequence.sequence.height = 180;
  sequence.sequence.grasp = 1;
  sequence.sequence.distance_m = 0.3;
  sequence.video = true;
  sequence.out_dir = dir / "sequence";
  RunSequence(sequence, nullptr);
  return dir;
}

}  // namespace nphand::testing

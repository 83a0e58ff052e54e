// Building the database: every (grasp, step, with/without object, viewpoint), then every
// (gesture, step, viewpoint) if gestures are asked for, rendered, segmented, cropped and
// described, in a fixed order, on all cores, deterministically.
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/db/database.h"
#include "nphand/features/descriptor.h"
#include "nphand/model/hand_model.h"
#include "nphand/scene/gesture.h"

namespace nphand {

struct DatabaseBuildOptions {
  std::vector<int> grasps;     // taxonomy numbers to include; empty: all 33
  std::vector<int> gestures = GestureIds();  // gestures' shape numbers to include (scene/gesture.h); empty: none
  int directions = 648;        // viewing directions on the sphere (the paper's count)
  int image_size = 128;        // rendered label image side, pixels
  double fov_deg = 30.0;       // horizontal field of view
  double distance = 0.5;       // camera to hand centre, metres
  // The stored descriptor (crop margin, roll normalisation, HOG 8 x 8 cells x 8 bins); its
  // crop_size must be kCropBitsSide. Roll is normalised by default and each entry's turn
  // stored, so that the in-plane roll of a query does not matter and can be recovered
  // (docs/feature_study.md measures why).
  DescriptorConfig descriptor;
  int threads = 0;             // 0: all cores
  int shard_index = 0;         // build only part shard_index of shard_count (contiguous)
  int shard_count = 1;

  bool Check(std::string* why) const;
  // Entries of the whole enumeration (all shards).
  uint64_t TotalEntries() const;
  // The header of the file these options build (no build time or machine: same options,
  // same bytes).
  nlohmann::json Header() const;
};

struct BuildSummary {
  uint64_t entries = 0;        // records in the finished file
  uint64_t resumed = 0;        // of which were already in a partial file
  uint64_t no_hand = 0;        // entries whose hand the object hides completely (this run)
  std::string resume_note;     // why a partial file was not (wholly) continued, if it was not
  double seconds = 0.0;
};

// Builds the database file at `path` (atomically). Checks `path` before any work. Resumes
// "<path>.partial" left by an interrupted build with the same options, keeping the blocks of
// records that still match their checksums; refuses to run while another build writes it. Reports progress (count, rate, ETA) to
// `progress` if not null.
BuildSummary BuildDatabase(const HandModel& hand, const DatabaseBuildOptions& options,
                           const std::filesystem::path& path, std::ostream* progress);

// Joins the shards of one build (any order) into the file an unsharded build would have
// written, byte for byte. Throws nphand::Error if they are not all the shards of one build.
void MergeDatabases(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& path);

// What a database file holds, for `nphand db info`: counts, features, sizes, and the view
// sphere's coverage (the largest angle between neighbouring directions, and from any
// direction to the nearest sampled one).
nlohmann::json DescribeDatabase(const Database& db);

}  // namespace nphand

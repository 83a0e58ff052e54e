// The files every command that estimates reads — the database, its index, the hand mesh —
// as one option group (--db, --index, --asset-dir) and one way to open them, with one set
// of messages for what is missing.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "nphand/db/database.h"
#include "nphand/index/knn_index.h"
#include "nphand/model/hand_model.h"
#include "nphand/util/file.h"

namespace nphand {

struct EstimatorFiles {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path index;  // default: the database's path + ".idx"
  std::filesystem::path asset_dir = DefaultAssetDir();

  std::filesystem::path IndexPath() const;
  // The database and its index, as inputs that no output may be.
  std::vector<NamedPath> Inputs() const;
  // Throws nphand::Error for a missing database or index, naming the command that makes it.
  void CheckPresent() const;
};

// The three opened in place (the index refers to the database): CheckPresent, then the
// database (verified), its index and the right hand's mesh.
struct OpenedFiles {
  explicit OpenedFiles(const EstimatorFiles& files);
  Database db;
  std::unique_ptr<KnnIndex> index;
  HandModel hand;
};

}  // namespace nphand

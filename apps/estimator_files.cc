#include "apps/estimator_files.h"

#include <system_error>

#include "apps/index_command.h"
#include "nphand/index/backends.h"
#include "nphand/util/check.h"

namespace nphand {

std::filesystem::path EstimatorFiles::IndexPath() const { return IndexPathOf(db, index); }

std::vector<NamedPath> EstimatorFiles::Inputs() const { return {{db, "--db"}, {IndexPath(), "--index"}}; }

void EstimatorFiles::CheckPresent() const {
  std::error_code error;
  NPHAND_THROW_CHECK(std::filesystem::exists(db, error), db.string(),
                     ": no database there (make one with `nphand db build`)");
  NPHAND_THROW_CHECK(std::filesystem::exists(IndexPath(), error), IndexPath().string(),
                     ": no index there (make one with `nphand index build --db ", db.string(), "`)");
}

namespace {

Database OpenPresent(const EstimatorFiles& files) {
  files.CheckPresent();
  return Database::Open(files.db);
}

}  // namespace

OpenedFiles::OpenedFiles(const EstimatorFiles& files)
    : db(OpenPresent(files)), index(LoadIndex(files.IndexPath(), db)),
      hand(HandModel::Load(Handedness::kRight, files.asset_dir)) {}

}  // namespace nphand

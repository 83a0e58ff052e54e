#include "nphand/index/backends.h"

#include <limits>

#include <gtest/gtest.h>

#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

class KnnIndexTest : public testing::TinyDatabaseTest {
 protected:
};

TEST_F(KnnIndexTest, ExactSearchReturnsTheTrueNearestInOrder) {
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), IndexOptions::Exact());
  EXPECT_EQ(index->Backend(), "exact");
  EXPECT_EQ(index->size(), DatabaseDescriptors(db()).ids.size());
  for (size_t q : {size_t{3}, size_t{77}, size_t{150}}) {
    const Neighbours found = index->Search(QueryOf(q), 10);
    ASSERT_EQ(found.ids.size(), 10u);
    EXPECT_EQ(found.ids[0], q) << "an entry is its own nearest";
    EXPECT_EQ(found.distances[0], 0.0f);
    // Brute force over every entry with a hand.
    std::vector<std::pair<float, entry_id_t>> all;
    for (size_t i = 0; i < db().size(); ++i) {
      if (db().Meta(i).has_hand) all.emplace_back(SquaredDistance(db().Hog(q), db().Hog(i)), i);
    }
    std::sort(all.begin(), all.end());
    for (int r = 0; r < 10; ++r) {
      EXPECT_EQ(found.ids[r], all[r].second) << r;
      EXPECT_FLOAT_EQ(found.distances[r], all[r].first) << r;
    }
  }
  EXPECT_EQ(index->Search(QueryOf(0), 100000).ids.size(), index->size()) << "k beyond the size gives all";
}

TEST_F(KnnIndexTest, BatchSearchEqualsOneAtATime) {
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), IndexOptions::Exact());
  std::vector<float> values;
  for (size_t q = 0; q < 20; ++q) values.insert(values.end(), db().Hog(q * 7).begin(), db().Hog(q * 7).end());
  const DescriptorMatrix queries(db().descriptor(), values);
  const std::vector<Neighbours> batch = index->SearchBatch(queries, 5, 2);
  for (size_t q = 0; q < 20; ++q) {
    const Neighbours one = index->Search(QueryOf(q * 7), 5);
    EXPECT_EQ(batch[q].ids, one.ids);
    EXPECT_EQ(batch[q].distances, one.distances);
  }
}

TEST_F(KnnIndexTest, QueryDescribedDifferentlyIsRefusedNamingBoth) {
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), IndexOptions::Exact());
  Descriptor query = QueryOf(3);
  query.config.normalize_roll = false;
  testing::ExpectError([&] { index->Search(query, 5); },
                       "the query: described as hog8x8x8, crop 64 px + 0.1 margin, roll as seen, but hog8x8x8, crop "
                       "64 px + 0.1 margin, roll-normalised is expected");
  testing::ExpectError([&] { index->Search(QueryOf(3), 0); }, "k must be at least 1");
  Descriptor broken = QueryOf(3);
  broken.values[100] = std::numeric_limits<float>::quiet_NaN();
  testing::ExpectError([&] { index->Search(broken, 5); }, "not a finite number");
}

TEST_F(KnnIndexTest, SavedIndexLoadsForItsDatabaseOnly) {
  const auto dir = testing::ScratchDir();
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), IndexOptions::Exact());
  index->Save(dir / "tiny.idx", db());
  const std::unique_ptr<KnnIndex> loaded = LoadIndex(dir / "tiny.idx", db());
  EXPECT_EQ(loaded->Search(QueryOf(9), 7).ids, index->Search(QueryOf(9), 7).ids);
  EXPECT_EQ(ReadIndexMeta(dir / "tiny.idx")["database"]["checksum"], db().checksum());

  DatabaseBuildOptions other = testing::TinyDatabaseOptions();
  other.directions = 6;
  BuildDatabase(testing::RightHand(), other, dir / "other.db", nullptr);
  testing::ExpectError([&] { LoadIndex(dir / "tiny.idx", Database::Open(dir / "other.db")); },
                       "tiny.idx: built from another database");
}

TEST_F(KnnIndexTest, CorruptTruncatedForeignAndFutureIndexFilesAreRefusedByName) {
  const auto dir = testing::ScratchDir();
  BuildIndex(db(), IndexOptions::Exact())->Save(dir / "good.idx", db());
  const std::vector<uint8_t> good = ReadFileBytes(dir / "good.idx");
  for (size_t i = 0; i < good.size(); ++i) {
    std::vector<uint8_t> bad = good;
    bad[i] ^= 0x20;
    WriteFileAtomic(dir / "bad.idx", bad);
    testing::ExpectError([&] { LoadIndex(dir / "bad.idx", db()); }, "bad.idx: ");
  }
  for (size_t length : {size_t{0}, size_t{7}, size_t{15}, good.size() / 2, good.size() - 1}) {
    WriteFileAtomic(dir / "cut.idx", std::span<const uint8_t>(good.data(), length));
    testing::ExpectError([&] { LoadIndex(dir / "cut.idx", db()); }, "cut.idx: ");
  }
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  WriteFileAtomic(dir / "long.idx", longer);
  testing::ExpectError([&] { LoadIndex(dir / "long.idx", db()); }, "long.idx: 1 bytes after the end");
  std::vector<uint8_t> future = good;
  future[8] = 2;
  WriteFileAtomic(dir / "future.idx", future);
  testing::ExpectError([&] { LoadIndex(dir / "future.idx", db()); }, "future.idx: index format version 2");
  testing::ExpectError([&] { LoadIndex(Path(), db()); }, "not an nphand index");
}

}  // namespace
}  // namespace nphand

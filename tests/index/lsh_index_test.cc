#include "nphand/index/lsh_index.h"

#include <algorithm>
#include <sstream>

#include <gtest/gtest.h>

#include "nphand/index/backends.h"
#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

class LshIndexTest : public testing::TinyDatabaseTest {
 protected:
  // Mean recall of `index`'s k nearest against exact search, over every `step`-th entry.
  static double Recall(const KnnIndex& index, int k, size_t first, size_t step) {
    const ExactIndex exact(DatabaseDescriptors(db()));
    double recall = 0.0;
    int queries = 0;
    for (size_t q = first; q < db().size(); q += step) {
      if (!db().Meta(q).has_hand) continue;
      std::vector<entry_id_t> truth = exact.Search(QueryOf(q), k).ids, found = index.Search(QueryOf(q), k).ids;
      std::sort(truth.begin(), truth.end());
      std::sort(found.begin(), found.end());
      std::vector<entry_id_t> common;
      std::set_intersection(truth.begin(), truth.end(), found.begin(), found.end(), std::back_inserter(common));
      recall += static_cast<double>(common.size()) / truth.size();
      ++queries;
    }
    return recall / queries;
  }
};

TEST_F(LshIndexTest, OneWideBucketIsExhaustiveAndEqualsExactSearch) {
  LshOptions options;
  options.tables = 1;
  options.probes = 1;
  options.hashes = 1;
  options.bucket_width = 1e5;
  const LshIndex lsh(DatabaseDescriptors(db()), options, nullptr);
  const ExactIndex exact(DatabaseDescriptors(db()));
  for (size_t q : {size_t{0}, size_t{41}, size_t{133}}) {
    const Neighbours a = lsh.Search(QueryOf(q), 20), b = exact.Search(QueryOf(q), 20);
    EXPECT_EQ(a.ids, b.ids);
    EXPECT_EQ(a.distances, b.distances);
  }
}

TEST_F(LshIndexTest, TunedIndexReachesItsRecallOnQueriesItWasNotTunedOn) {
  LshOptions options;
  options.tune_k = 10;
  options.tune_queries = 40;
  options.target_recall = 0.9;
  options.tables = 4;
  options.probes = 8;
  std::ostringstream log;
  const LshIndex lsh(DatabaseDescriptors(db()), options, &log);
  EXPECT_GE(lsh.tuned_recall(), 0.9);
  EXPECT_NE(log.str().find("lsh tuning: M = "), std::string::npos);
  const nlohmann::json parameters = lsh.Parameters();
  EXPECT_GT(parameters["hashes"].get<int>(), 0);
  EXPECT_GT(parameters["bucket_width"].get<double>(), 0.0);
  EXPECT_LT(parameters["tuned_candidates"].get<double>(), static_cast<double>(lsh.size()))
      << "tuning must not end in exhaustive search";
  // All entries, most of which the tuner never saw; the sample's recall carries over.
  EXPECT_GE(Recall(lsh, 10, 0, 1), 0.85);
  // Same seed, same index.
  EXPECT_EQ(LshIndex(DatabaseDescriptors(db()), options, nullptr).Parameters(), parameters);
}

TEST_F(LshIndexTest, MoreProbesNeverLoseNeighbours) {
  LshOptions options;
  options.tables = 2;
  options.hashes = 8;
  options.bucket_width = 0.25;
  options.probes = 1;
  const double one = Recall(LshIndex(DatabaseDescriptors(db()), options, nullptr), 10, 0, 3);
  options.probes = 30;
  const double many = Recall(LshIndex(DatabaseDescriptors(db()), options, nullptr), 10, 0, 3);
  EXPECT_GE(many, one);
  EXPECT_GT(many, one) << "probing neighbouring buckets finds more (" << one << " -> " << many << ")";
}

TEST_F(LshIndexTest, SavedIndexLoadsToTheSameSearch) {
  const auto dir = testing::ScratchDir();
  IndexOptions options;
  options.backend = "lsh";
  options.lsh.tune_k = 10;
  options.lsh.tune_queries = 30;
  options.lsh.tables = 3;
  options.lsh.probes = 5;
  const std::unique_ptr<KnnIndex> built = BuildIndex(db(), options);
  built->Save(dir / "lsh.idx", db());
  const std::unique_ptr<KnnIndex> loaded = LoadIndex(dir / "lsh.idx", db());
  EXPECT_EQ(loaded->Backend(), "lsh");
  for (size_t q : {size_t{5}, size_t{99}}) EXPECT_EQ(loaded->Search(QueryOf(q), 10).ids, built->Search(QueryOf(q), 10).ids);
  EXPECT_EQ(ReadIndexMeta(dir / "lsh.idx")["parameters"]["hashes"], built->Parameters()["hashes"]);
}

TEST(LshOptionsTest, BadOptionsAreRefused) {
  LshOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.hashes = kMaxLshHashes + 1;
  EXPECT_FALSE(options.Check(&why));
  options = {};
  options.target_recall = 1.5;
  EXPECT_FALSE(options.Check(&why));
  options = {};
  options.tables = 0;
  EXPECT_FALSE(options.Check(&why));
  testing::ExpectError([] { LshIndex::OptionsFromParameters({{"tables", 10}}, "x.idx"); }, "x.idx: the LSH parameters");
}

}  // namespace
}  // namespace nphand

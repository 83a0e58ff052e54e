#include "nphand/eval/ann_study.h"

#include <gtest/gtest.h>

#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

class AnnStudyTest : public testing::TinyDatabaseTest {};

TEST_F(AnnStudyTest, HeldOutQueriesAreNotDatabaseEntries) {
  const std::vector<HeldOutQuery> queries = RenderHeldOutQueries(testing::RightHand(), db(), 12, 3);
  ASSERT_EQ(queries.size(), 12u);
  for (const HeldOutQuery& q : queries) {
    EXPECT_EQ(q.descriptor.config, db().descriptor());
    double nearest_joint = 1e9;
    for (size_t i = 0; i < db().size(); ++i) {
      const JointAngles angles = db().Angles(i);
      double joint = 0.0;
      for (int d = 0; d < kNumDofs; ++d) joint += std::abs(angles[d] - q.angles[d]);
      nearest_joint = std::min(nearest_joint, joint);
    }
    EXPECT_GT(nearest_joint, 1e-6) << "a pose between the database's steps";
  }
  const std::vector<HeldOutQuery> again = RenderHeldOutQueries(testing::RightHand(), db(), 12, 3);
  EXPECT_EQ(again[5].descriptor.values, queries[5].descriptor.values) << "seeded";
}

TEST_F(AnnStudyTest, ExactFindsItselfAndEveryRowIsMeasured) {
  AnnStudyOptions options;
  options.fractions = {0.5, 1.0};
  options.configs = {"exact", "hnswlib", "faiss-ivf"};
  options.queries = 10;
  options.k = 20;
  const AnnStudyResult result = RunAnnStudy(testing::RightHand(), db(), options, nullptr);
  ASSERT_EQ(result.rows.size(), 6u);
  for (const AnnRow& row : result.rows) {
    EXPECT_GT(row.entries, 0u);
    EXPECT_GE(row.recall, 0.0);
    EXPECT_LE(row.recall, 1.0);
    EXPECT_GT(row.ms_median, 0.0);
    EXPECT_EQ(row.unanswered, 0u);
    EXPECT_GE(row.joint_deg, 0.0);
    EXPECT_TRUE(row.backend != "exact" || row.recall == 1.0) << "exact is its own truth";
  }
  EXPECT_LT(result.rows[0].entries, result.rows[3].entries) << "fractions grow";
  const nlohmann::json json = ToJson(result);
  for (const char* field : {"recall_at_k", "ms_per_query", "build_s", "index_bytes"}) {
    EXPECT_TRUE(json["rows"][0].contains(field)) << field;
  }
  EXPECT_NE(FormatTable(result).find("hnswlib"), std::string::npos);
  EXPECT_FALSE(PlotAnnStudy(result).empty());
}

TEST_F(AnnStudyTest, BadOptionsAreNamed) {
  AnnStudyOptions options;
  options.fractions = {0.0};
  testing::ExpectError([&] { RunAnnStudy(testing::RightHand(), db(), options, nullptr); },
                       "database fractions must be in (0, 1]");
  options.fractions = {1.0};
  options.configs = {"annoy"};
  testing::ExpectError([&] { RunAnnStudy(testing::RightHand(), db(), options, nullptr); },
                       "unknown backend setting 'annoy'");
}

}  // namespace
}  // namespace nphand

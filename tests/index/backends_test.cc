// Every index backend against the exact index: exhaustive settings give its neighbours,
// approximate settings reach a recall floor on rows the index does not hold, a saved index
// loads back to the same answers, and forged bodies are refused by name.
#include "nphand/index/backends.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "nphand/index/body.h"
#include "nphand/index/exact_index.h"
#include "nphand/index/index_file.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

struct BackendCase {
  std::string name;
  IndexOptions exhaustive;   // settings under which the backend searches everything
  IndexOptions approximate;  // settings that search part of the index
  double recall_floor;       // of the true 10 nearest, on rows the index does not hold
  // Whether a loaded index answers as the built one did: Debian's FLANN seeds its shuffles
  // from std::random_device, so its trees, rebuilt at load, differ from build to build.
  bool reproducible = true;
  // Whether it searches 8-bit codes of the rows: its distances are the codes'.
  bool quantized = false;
};

void PrintTo(const BackendCase& c, std::ostream* out) { *out << c.name; }

std::vector<BackendCase> Cases() {
  std::vector<BackendCase> cases;
  auto add = [&](const std::string& name, auto configure_exhaustive, auto configure_approximate, double floor) {
    BackendCase c{name, {}, {}, floor};
    c.exhaustive.backend = c.approximate.backend = name.substr(0, name.find('/'));
    configure_exhaustive(c.exhaustive);
    configure_approximate(c.approximate);
    cases.push_back(c);
  };
  add("exact", [](IndexOptions&) {}, [](IndexOptions&) {}, 1.0);
  add("lsh",
      [](IndexOptions& o) {
        o.lsh.tables = 1, o.lsh.probes = 1, o.lsh.hashes = 1, o.lsh.bucket_width = 1e6;  // one bucket
      },
      [](IndexOptions& o) {  // tuned for 0.9 of the true 10 nearest on rows it holds
        o.lsh.tables = 4, o.lsh.probes = 8, o.lsh.target_recall = 0.9, o.lsh.tune_k = 10, o.lsh.tune_queries = 40;
      },
      0.5);
  for (const char* hnsw : {"faiss-hnsw", "hnswlib"}) {
    add(hnsw, [](IndexOptions& o) { o.hnsw.ef_search = 1000; },
        [](IndexOptions& o) { o.hnsw.m = 4, o.hnsw.ef_construction = 16, o.hnsw.ef_search = 10; }, 0.7);
  }
  add("hnswlib-sq8", [](IndexOptions& o) { o.hnsw.ef_search = 1000; },
      [](IndexOptions& o) { o.hnsw.m = 4, o.hnsw.ef_construction = 16, o.hnsw.ef_search = 10; }, 0.7);
  cases.back().quantized = true;
  add("hnswlib/pca", [](IndexOptions& o) { o.hnsw.pca = 16, o.hnsw.ef_search = 1000; },
      [](IndexOptions& o) { o.hnsw.pca = 16, o.hnsw.m = 4, o.hnsw.ef_construction = 16, o.hnsw.ef_search = 20; }, 0.6);
  for (const char* encoding : {"flat", "sq8"}) {
    add(std::string("faiss-ivf/") + encoding,
        [&](IndexOptions& o) { o.ivf.lists = 8, o.ivf.probes = 8, o.ivf.encoding = encoding; },
        [&](IndexOptions& o) { o.ivf.lists = 8, o.ivf.probes = 3, o.ivf.encoding = encoding; }, 0.6);
  }
  for (const char* algorithm : {"kdtree", "kmeans"}) {
    add(std::string("flann/") + algorithm,
        [&](IndexOptions& o) { o.flann.algorithm = algorithm, o.flann.checks = -1, o.flann.branching = 4; },
        [&](IndexOptions& o) { o.flann.algorithm = algorithm, o.flann.checks = 64, o.flann.branching = 4; }, 0.5);
    cases.back().reproducible = false;
  }
  return cases;
}

class BackendTest : public testing::TinyDatabaseTest, public ::testing::WithParamInterface<BackendCase> {};

// The rows of the tiny database's set whose position has the given parity.
IndexedSet Half(const IndexedSet& all, int parity) {
  std::vector<float> values;
  IndexedSet half{DescriptorMatrix(all.descriptors.config(), 0), {}};
  for (size_t r = parity; r < all.ids.size(); r += 2) {
    values.insert(values.end(), all.descriptors.Row(r).begin(), all.descriptors.Row(r).end());
    half.ids.push_back(all.ids[r]);
  }
  half.descriptors = DescriptorMatrix(all.descriptors.config(), std::move(values));
  return half;
}

TEST_P(BackendTest, ExhaustiveSettingsGiveTheExactNeighbours) {
  const std::unique_ptr<KnnIndex> exact = BuildIndex(db(), IndexOptions::Exact());
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), GetParam().exhaustive);
  EXPECT_EQ(index->Backend(), GetParam().exhaustive.backend);
  for (size_t q : {size_t{0}, size_t{31}, size_t{77}, size_t{150}}) {
    for (int k : {1, 10, 40}) {
      const Neighbours want = exact->Search(QueryOf(q), k), got = index->Search(QueryOf(q), k);
      if (GetParam().quantized) {
        // Each distance is its entry's true one but for the codes' rounding; the entries
        // are among the true k nearest (ties included) but where rounding swaps near-equal
        // ones.
        const Neighbours all = exact->Search(QueryOf(q), static_cast<int>(exact->size()));
        size_t found = 0;
        for (size_t r = 0; r < got.ids.size(); ++r) {
          const auto at = std::find(all.ids.begin(), all.ids.end(), got.ids[r]) - all.ids.begin();
          EXPECT_NEAR(got.distances[r], all.distances[at], 0.01) << q << " k=" << k;
          found += all.distances[at] <= want.distances.back();
        }
        EXPECT_GE(static_cast<double>(found), 0.9 * k) << q << " k=" << k;
        continue;
      }
      ASSERT_EQ(got.distances, want.distances) << q << " k=" << k;
      // Entries at the k-th distance tie (a hand the object does not touch looks the same
      // with and without it); below it the entries must agree.
      for (int r = 0; r < k; ++r) {
        if (want.distances[r] < want.distances.back()) {
          EXPECT_EQ(got.ids[r], want.ids[r]) << q << " rank " << r;
        }
      }
    }
  }
}

TEST_P(BackendTest, ApproximateSettingsReachTheirRecallOnRowsTheyDoNotHold) {
  const IndexedSet all = DatabaseDescriptors(db());
  const IndexedSet queries = Half(all, 1);
  const std::unique_ptr<KnnIndex> exact = BuildIndex(Half(all, 0), IndexOptions::Exact());
  const std::unique_ptr<KnnIndex> index = BuildIndex(Half(all, 0), GetParam().approximate);
  const std::vector<Neighbours> want = exact->SearchBatch(queries.descriptors, 10);
  const std::vector<Neighbours> got = index->SearchBatch(queries.descriptors, 10);
  size_t found = 0, total = 0;
  for (size_t q = 0; q < want.size(); ++q) {
    const std::set<entry_id_t> truth(want[q].ids.begin(), want[q].ids.end());
    for (entry_id_t id : got[q].ids) found += truth.count(id);
    total += truth.size();
  }
  EXPECT_GE(static_cast<double>(found) / total, GetParam().recall_floor);
}

TEST_P(BackendTest, SavedIndexLoadsToTheSameAnswersAndBytes) {
  const auto dir = testing::ScratchDir();
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), GetParam().approximate);
  index->Save(dir / "a.idx", db());
  const std::unique_ptr<KnnIndex> loaded = LoadIndex(dir / "a.idx", db());
  EXPECT_EQ(loaded->Backend(), index->Backend());
  EXPECT_EQ(loaded->Parameters(), index->Parameters());
  const std::unique_ptr<KnnIndex> exact = BuildIndex(db(), IndexOptions::Exact());
  size_t found = 0, total = 0;
  for (size_t q : {size_t{5}, size_t{60}, size_t{140}}) {
    const Neighbours a = index->Search(QueryOf(q), 10), b = loaded->Search(QueryOf(q), 10);
    if (GetParam().reproducible) {
      EXPECT_EQ(a.ids, b.ids);
      EXPECT_EQ(a.distances, b.distances);
    }
    const Neighbours truth = exact->Search(QueryOf(q), 10);
    for (entry_id_t id : b.ids) found += std::count(truth.ids.begin(), truth.ids.end(), id);
    total += truth.ids.size();
  }
  EXPECT_GE(static_cast<double>(found) / total, GetParam().recall_floor) << "trees built anew keep their recall";
  loaded->Save(dir / "b.idx", db());
  BuildIndex(db(), GetParam().approximate)->Save(dir / "c.idx", db());
  EXPECT_EQ(ReadFileBytes(dir / "a.idx"), ReadFileBytes(dir / "b.idx")) << "load keeps everything";
  EXPECT_EQ(ReadFileBytes(dir / "a.idx"), ReadFileBytes(dir / "c.idx")) << "same options, same bytes";
}

TEST_P(BackendTest, BatchSearchEqualsOneAtATime) {
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), GetParam().approximate);
  const IndexedSet all = DatabaseDescriptors(db());
  const std::vector<Neighbours> batch = index->SearchBatch(all.descriptors, 7, 2);
  for (size_t r = 0; r < all.ids.size(); r += 13) {
    const Neighbours one = index->Search(QueryOf(all.ids[r]), 7);
    EXPECT_EQ(batch[r].ids, one.ids);
    EXPECT_EQ(batch[r].distances, one.distances);
  }
}

// A search with less effort: hnswlib's (codes or floats) is the search of an index whose
// ef_search is that effort (the same graph: its build does not read ef_search); every
// other backend searches as it always does. An effort under 1 is refused.
TEST_P(BackendTest, ASearchWithLessEffortSearchesWithThatCandidateList) {
  IndexOptions options = GetParam().approximate;
  options.hnsw.ef_search = 200;
  const std::unique_ptr<KnnIndex> index = BuildIndex(db(), options);
  const bool graph = (options.backend == "hnswlib" || options.backend == "hnswlib-sq8") && options.hnsw.pca == 0;
  constexpr int kEffort = 12;
  IndexOptions narrow_options = options;
  narrow_options.hnsw.ef_search = kEffort;
  const std::unique_ptr<KnnIndex> narrow = graph ? BuildIndex(db(), narrow_options) : nullptr;
  const IndexedSet all = DatabaseDescriptors(db());
  size_t differ = 0;
  for (size_t r = 0; r < all.ids.size(); r += 17) {
    for (int k : {1, 10}) {
      const Neighbours got = index->Search(QueryOf(all.ids[r]), k, kEffort);
      const Neighbours want = graph ? narrow->Search(QueryOf(all.ids[r]), k) : index->Search(QueryOf(all.ids[r]), k);
      EXPECT_EQ(got.ids, want.ids) << r << " k=" << k;
      EXPECT_EQ(got.distances, want.distances) << r << " k=" << k;
      differ += graph && got.ids != index->Search(QueryOf(all.ids[r]), k).ids;
    }
  }
  if (graph) {
    EXPECT_GT(differ, 0u) << "a candidate list of " << kEffort << " finds what one of 200 does on every query";
  }
  testing::ExpectError([&] { index->Search(QueryOf(all.ids[0]), 5, 0); }, "the effort must be at least 1");
}

// Distances to chosen entries are measured as the search measures them: those of the
// entries a search found are its own; an entry the index does not hold is refused by name.
TEST_P(BackendTest, DistancesToChosenEntriesAreTheSearchsOwn) {
  const IndexedSet all = DatabaseDescriptors(db());
  const std::unique_ptr<KnnIndex> index = BuildIndex(Half(all, 0), GetParam().approximate);
  for (size_t q : {size_t{1}, size_t{64}, size_t{151}}) {
    const Neighbours found = index->Search(QueryOf(all.ids[q]), 12);
    std::vector<entry_id_t> ids(found.ids.rbegin(), found.ids.rend());  // in another order
    std::vector<float> distances;
    ASSERT_TRUE(index->Distances(QueryOf(all.ids[q]), ids, &distances));
    ASSERT_EQ(distances.size(), ids.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      const float want = found.distances[found.ids.size() - 1 - i];
      EXPECT_NEAR(distances[i], want, 1e-5f * std::max(1.0f, want)) << q << " entry " << ids[i];
    }
  }
  std::vector<float> untouched = {7.0f};
  testing::ExpectError([&] { index->Distances(QueryOf(all.ids[0]), std::vector<entry_id_t>{all.ids[1]}, &untouched); },
                       "entry " + std::to_string(all.ids[1]) + " is not in the index");
  const entry_id_t beyond = all.ids.back() + 1000;  // past the largest entry held
  testing::ExpectError([&] { index->Distances(QueryOf(all.ids[0]), std::vector<entry_id_t>{beyond}, &untouched); },
                       "entry " + std::to_string(beyond) + " is not in the index");
  EXPECT_EQ(untouched, std::vector<float>{7.0f});
}

// An index's entries are ascending, as the database's are: a set out of order is refused.
TEST_P(BackendTest, EntriesOutOfOrderAreRefused) {
  IndexedSet set = Half(DatabaseDescriptors(db()), 0);
  std::swap(set.ids[0], set.ids[1]);
  testing::ExpectError([&] { BuildIndex(std::move(set), GetParam().approximate); }, "its entries must be ascending");
}

INSTANTIATE_TEST_SUITE_P(All, BackendTest, ::testing::ValuesIn(Cases()), [](const auto& info) {
  std::string name = info.param.name;
  for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
});

class ForgedBodyTest : public testing::TinyDatabaseTest {
 protected:
  // A file with `body` in place of the real one, its checksum valid.
  std::filesystem::path Forge(const std::string& backend, const std::vector<uint8_t>& body) {
    const auto path = testing::ScratchDir() / "forged.idx";
    IndexOptions options;
    options.backend = backend;
    const auto real = testing::ScratchDir() / "real.idx";
    BuildIndex(db(), options)->Save(real, db());
    WriteIndexFile(path, ReadIndexFile(real).meta, body);
    return path;
  }
  std::vector<uint8_t> RealBody(const std::string& backend) {
    IndexOptions options;
    options.backend = backend;
    const auto real = testing::ScratchDir() / "real.idx";
    BuildIndex(db(), options)->Save(real, db());
    return ReadIndexFile(real).body;
  }
};

TEST_F(ForgedBodyTest, GraphsWithLinksOutsideTheirLevelAreRefused) {
  for (const std::string backend : {"faiss-hnsw", "hnswlib", "hnswlib-sq8"}) {
    const std::vector<uint8_t> body = RealBody(backend);
    // The body ends with the link values; point the last one at a node that does not exist.
    std::vector<uint8_t> bad = body;
    const uint32_t n = 1000000;
    std::memcpy(bad.data() + bad.size() - 4, &n, 4);
    testing::ExpectError([&] { LoadIndex(Forge(backend, bad), db()); }, "forged.idx: an HNSW link");
    testing::ExpectError([&] { LoadIndex(Forge(backend, std::vector<uint8_t>(body.begin(), body.end() - 1)), db()); },
                         "forged.idx: ");
    std::vector<uint8_t> longer = body;
    longer.push_back(0);
    testing::ExpectError([&] { LoadIndex(Forge(backend, longer), db()); }, "forged.idx: ");
    testing::ExpectError([&] { LoadIndex(Forge(backend, {}), db()); }, "forged.idx: the index body is truncated");
  }
}

TEST_F(ForgedBodyTest, CodeStepsThatAreNotPositiveAreRefused) {
  const std::vector<uint8_t> body = RealBody("hnswlib-sq8");
  for (float step : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN()}) {
    std::vector<uint8_t> bad = body;
    std::memcpy(bad.data(), &step, 4);
    testing::ExpectError([&] { LoadIndex(Forge("hnswlib-sq8", bad), db()); }, "forged.idx: the 8-bit code step");
  }
}

// Rows whose values are whole steps are coded without loss: the codes' search is the
// exact search.
TEST_F(ForgedBodyTest, RowsOfWholeStepsAreSearchedExactly) {
  IndexedSet set = DatabaseDescriptors(db());
  std::vector<float> values = set.descriptors.values();
  const float step = *std::max_element(values.begin(), values.end()) / 255.0f;
  for (float& v : values) v = std::round(v / step) * step;
  const DescriptorConfig config = set.descriptors.config();
  const IndexedSet whole{DescriptorMatrix(config, values), set.ids};
  const std::unique_ptr<KnnIndex> exact = BuildIndex(whole, IndexOptions::Exact());
  IndexOptions options;
  options.backend = "hnswlib-sq8";
  options.hnsw.ef_search = 1000;
  const std::unique_ptr<KnnIndex> coded = BuildIndex(whole, options);
  for (size_t r = 0; r < whole.ids.size(); r += 17) {
    const Descriptor query{config, std::vector<float>(whole.descriptors.Row(r).begin(), whole.descriptors.Row(r).end()), 0.0};
    const Neighbours want = exact->Search(query, 20), got = coded->Search(query, 20);
    ASSERT_EQ(got.ids.size(), want.ids.size());
    for (size_t i = 0; i < want.ids.size(); ++i) {
      EXPECT_NEAR(got.distances[i], want.distances[i], 1e-5f * (1.0f + want.distances[i])) << r << " rank " << i;
      if (want.distances[i] < want.distances.back() - 1e-5f) {
        EXPECT_EQ(got.ids[i], want.ids[i]) << r << " rank " << i;
      }
    }
  }
}

TEST_F(ForgedBodyTest, CellsOutsideTheListsAreRefused) {
  const std::vector<uint8_t> body = RealBody("faiss-ivf");
  std::vector<uint8_t> bad = body;
  const int32_t cell = 1 << 20;
  std::memcpy(bad.data() + bad.size() - 4, &cell, 4);
  testing::ExpectError([&] { LoadIndex(Forge("faiss-ivf", bad), db()); }, "forged.idx: a row's cell 1048576");
}

TEST_F(ForgedBodyTest, BackendsWithoutABodyRefuseOne) {
  for (const std::string backend : {"exact", "lsh", "flann"}) {
    testing::ExpectError([&] { LoadIndex(Forge(backend, {1, 2, 3}), db()); }, "has no body, the file holds 3 bytes");
  }
}

TEST(BodyReaderTest, LengthsAreCheckedBeforeAnyAllocation) {
  BodyWriter writer;
  writer.Put<uint64_t>(uint64_t{1} << 60);  // a count far beyond the bytes that follow
  const std::vector<uint8_t> bytes = writer.Take();
  BodyReader reader(bytes, "x.idx");
  testing::ExpectError([&] { reader.GetArrayAtMost<float>(uint64_t{1} << 62, "values"); }, "x.idx: the index body is truncated");
  BodyReader again(bytes, "x.idx");
  testing::ExpectError([&] { again.GetArray<float>(3, "values"); }, "x.idx: the index body holds 1152921504606846976 values, at most 3");
}

}  // namespace
}  // namespace nphand

#include "nphand/db/builder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <set>

#include "nphand/render/renderer.h"
#include "nphand/scene/gesture.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/parallel.h"
#include "nphand/util/progress.h"

namespace nphand {
namespace {

constexpr size_t kBatch = 1024;

std::vector<int> GraspsOf(const DatabaseBuildOptions& options) {
  if (!options.grasps.empty()) return options.grasps;
  std::vector<int> all(kNumGrasps);
  for (int i = 0; i < kNumGrasps; ++i) all[i] = i + 1;
  return all;
}

std::pair<uint64_t, uint64_t> ShardRange(const DatabaseBuildOptions& options) {
  const uint64_t total = options.TotalEntries();
  return {total * options.shard_index / options.shard_count, total * (options.shard_index + 1) / options.shard_count};
}

// Everything an entry needs that does not change between entries.
struct Context {
  const HandModel& hand;
  const DatabaseBuildOptions& options;
  Enumeration enumeration;
  // Per hand shape, in the enumeration's order (grasps, then gestures): its steps' angles,
  // and its object (none for a gesture).
  std::vector<std::array<JointAngles, kGraspSteps>> steps;
  std::vector<SceneObject> objects;
  std::vector<Eigen::Vector3d> directions;
  Intrinsics intrinsics;
  RecordLayout layout;
};

// Entry `index` of the enumeration (see Enumeration).
void RenderEntry(const Context& c, uint64_t index, Renderer* renderer, cv::Mat* labels, std::span<uint8_t> record,
                 uint64_t* no_hand) {
  Entry entry;
  entry.meta = c.enumeration.At(index);
  const size_t shape = c.enumeration.ShapePosition(index);

  Scene scene;
  scene.hand.handedness = c.hand.handedness();
  scene.hand.angles = c.steps[shape][entry.meta.step];
  scene.hand.camera_from_hand = CameraFromHand(ViewpointFromDirection(c.directions[entry.meta.viewpoint]));
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, c.hand.bind_centre(), c.options.distance);
  if (entry.meta.with_object) scene.objects = {c.objects[shape]};
  renderer->RenderLabels(scene, c.intrinsics, labels);

  entry.pose = ToPoseVector(scene.hand);
  entry.angles = scene.hand.angles;
  entry.keypoints = c.hand.KeypointsOf(scene.hand);
  const cv::Mat mask = *labels == static_cast<int>(PixelLabel::kHand);
  const std::optional<HandCrop> crop = CropHand(mask, {kCropBitsSide, c.options.descriptor.crop_margin});
  if (crop.has_value()) {
    const Descriptor descriptor = *Describe(mask, c.options.descriptor);
    entry.meta.has_hand = true;
    entry.meta.roll = static_cast<float>(descriptor.roll);
    entry.hog = descriptor.values;
    entry.crop = crop->image >= 0.5f;
  } else {
    ++*no_hand;
    entry.hog.assign(c.layout.hog_dimension, 0.0f);
    entry.crop = cv::Mat::zeros(kCropBitsSide, kCropBitsSide, CV_8UC1);
  }
  EncodeEntry(entry, c.layout, record);
}

// The view sphere's coverage, rounded so that the header's bytes do not hang on the last
// bits of a floating-point sum.
nlohmann::json CoverageJson(int directions) {
  const ViewSphereCoverage coverage = MeasureCoverage(ViewSphereDirections(directions));
  const auto round = [](double degrees) { return std::round(degrees * 1e4) / 1e4; };
  return {{"max_neighbour_deg", round(coverage.max_neighbour_deg)},
          {"covering_radius_deg", round(coverage.covering_radius_deg)}};
}

}  // namespace

bool DatabaseBuildOptions::Check(std::string* why) const {
  for (int id : grasps) {
    if (id < 1 || id > kNumGrasps) {
      *why = "grasp numbers run from 1 to 33, got " + std::to_string(id);
      return false;
    }
  }
  if (std::set<int>(grasps.begin(), grasps.end()).size() != grasps.size()) {
    *why = "a grasp is listed twice";
    return false;
  }
  for (int id : gestures) {
    if (!IsGesture(id)) {
      *why = "gestures are hand shapes " + std::to_string(kFirstGestureId) + " to " + std::to_string(kNumHandShapes) +
             ", got " + std::to_string(id);
      return false;
    }
  }
  if (std::set<int>(gestures.begin(), gestures.end()).size() != gestures.size()) {
    *why = "a gesture is listed twice";
    return false;
  }
  if (directions < 2 || directions > 65535) {
    *why = "directions must be between 2 and 65535";
    return false;
  }
  if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count) {
    *why = "shard must be i/N with 0 <= i < N";
    return false;
  }
  if (threads < 0 || threads > 256) {
    *why = "threads must be between 0 (all cores) and 256";
    return false;
  }
  const Intrinsics intrinsics = Intrinsics::FromFieldOfView(image_size, image_size, fov_deg * std::numbers::pi / 180.0);
  if (!(distance > 0.1 && distance < 10.0) || !(fov_deg > 5.0 && fov_deg < 120.0)) {
    *why = "distance must be within (0.1, 10) metres and the field of view within (5, 120) degrees";
    return false;
  }
  if (descriptor.crop_size != kCropBitsSide) {
    *why = "the descriptor's crop must be the stored crop's side, " + std::to_string(kCropBitsSide);
    return false;
  }
  return descriptor.Check(why) && intrinsics.Check(why);
}

uint64_t DatabaseBuildOptions::TotalEntries() const {
  return (static_cast<uint64_t>(GraspsOf(*this).size()) * 2 + gestures.size()) * kGraspSteps *
         static_cast<uint64_t>(directions);
}

nlohmann::json DatabaseBuildOptions::Header() const {
  RecordLayout layout;
  layout.hog_dimension = descriptor.Dimension();
  const auto [begin, end] = ShardRange(*this);
  nlohmann::json objects = nlohmann::json::array();
  for (int id : GraspsOf(*this)) {
    const GraspDefinition& g = GraspTaxonomy()[id - 1];
    const std::vector<double> size(g.object.size.begin(), g.object.size.begin() + ObjectSizeCount(g.object.shape));
    objects.push_back({{"grasp", id}, {"name", GraspKey(g)}, {"object", ToString(g.object.shape)}, {"size_m", size}});
  }
  nlohmann::json header = {
      {"format", "nphand database"},
      {"grasp_objects", objects},
      {"entries", end - begin},
      {"total_entries", TotalEntries()},
      {"record_bytes", layout.RecordBytes()},
      {"order", "((grasp * steps + step) * 2 + with_object) * viewpoints + viewpoint"},
      {"grasps", GraspsOf(*this)},
      {"steps", kGraspSteps},
      {"viewpoints", directions},
      {"view_sphere", "fibonacci"},
      {"view_sphere_coverage", CoverageJson(directions)},
      {"hand", "right"},
      {"hand_asset_sha256", PinnedAssetSha256(Handedness::kRight)},
      {"keypoints", kKeypointRule},
      {"render", {{"image_size", image_size}, {"fov_deg", fov_deg}, {"distance_m", distance}}},
      {"crop", {{"size", descriptor.crop_size}, {"margin", descriptor.crop_margin}}},
  };
  // The descriptor's HOG block, with its roll normalisation in it (the file's layout).
  header["hog"] = ToJson(descriptor)["hog"];
  header["hog"]["normalize_roll"] = descriptor.normalize_roll;
  if (!gestures.empty()) {  // a build without gestures keeps the bytes of the files before them
    header["gestures"] = gestures;
    std::vector<std::string> names;
    for (int id : gestures) names.push_back(HandShapeKey(id));
    header["gesture_names"] = names;
    header["order"] = header["order"].get<std::string>() +
                      ", then grasp entries + (gesture * steps + step) * viewpoints + viewpoint";
  }
  if (shard_count > 1) {
    header["shard"] = {{"index", shard_index}, {"count", shard_count}, {"begin", begin}, {"end", end}};
  }
  return header;
}

BuildSummary BuildDatabase(const HandModel& hand, const DatabaseBuildOptions& options, const std::filesystem::path& path,
                           std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "db build: ", why);
  NPHAND_THROW_CHECK(hand.handedness() == Handedness::kRight, "db build: the database is built from the right hand");
  CheckOutputFile(path, "db build --out");
  const auto start = std::chrono::steady_clock::now();

  const nlohmann::json header = options.Header();
  Context c{hand, options, Enumeration(header), {}, {}, ViewSphereDirections(options.directions),
            Intrinsics::FromFieldOfView(options.image_size, options.image_size, options.fov_deg * std::numbers::pi / 180.0),
            {}};
  c.layout.hog_dimension = options.descriptor.Dimension();
  for (int id : c.enumeration.grasps) {
    const Grasp grasp = MakeGrasp(hand, GraspTaxonomy()[id - 1]);
    c.steps.push_back(grasp.steps);
    c.objects.push_back(grasp.object);
  }
  for (int id : c.enumeration.gestures) {
    c.steps.push_back(GestureSteps(Gestures()[id - kFirstGestureId]));
    c.objects.emplace_back();
  }

  DatabaseWriter writer(path, header, DatabaseWriter::Mode::kResume);
  const auto [begin, end] = ShardRange(options);
  BuildSummary summary;
  summary.resumed = writer.records_written();
  summary.resume_note = writer.resume_note();
  if (progress != nullptr && !summary.resume_note.empty()) *progress << "db build: " << summary.resume_note << "\n";

  const int threads = ThreadCount(options.threads);
  const size_t record_bytes = c.layout.RecordBytes();
  std::vector<uint8_t> batch(kBatch * record_bytes);
  std::vector<Renderer> renderers(threads, Renderer(hand));
  std::vector<cv::Mat> labels(threads);
  std::vector<uint64_t> no_hand(threads, 0);
  ProgressLine line(progress, "db build", end - begin, "entries", summary.resumed);
  for (uint64_t first = begin + summary.resumed; first < end; first += kBatch) {
    const uint64_t count = std::min<uint64_t>(kBatch, end - first);
    ParallelFor(count, threads, [&](size_t i, int worker) {
      RenderEntry(c, first + i, &renderers[worker], &labels[worker],
                  std::span<uint8_t>(batch.data() + i * record_bytes, record_bytes), &no_hand[worker]);
    });
    writer.Append(std::span<const uint8_t>(batch.data(), count * record_bytes));
    line.Update(writer.records_written());
  }
  line.Finish();
  summary.entries = writer.records_written();
  writer.Finish();
  for (uint64_t n : no_hand) summary.no_hand += n;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

void MergeDatabases(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& path) {
  NPHAND_THROW_CHECK(!shards.empty(), "db merge: no shards given");
  CheckOutputFile(path, "db merge --out");
  std::vector<Database> parts;
  for (const auto& shard : shards) {
    parts.push_back(Database::Open(shard));
    NPHAND_THROW_CHECK(parts.back().header().contains("shard"), shard.string(), ": not a shard");
  }
  std::sort(parts.begin(), parts.end(), [](const Database& a, const Database& b) {
    return a.header()["shard"]["index"].get<int>() < b.header()["shard"]["index"].get<int>();
  });
  const auto common = [](nlohmann::json header) {
    header.erase("shard");
    header.erase("entries");
    return header;
  };
  const int count = parts.front().header()["shard"]["count"].get<int>();
  NPHAND_THROW_CHECK(static_cast<int>(parts.size()) == count, "db merge: ", parts.size(), " shards given, the build has ",
                     count);
  uint64_t next = 0;
  for (int i = 0; i < count; ++i) {
    const nlohmann::json& shard = parts[i].header()["shard"];
    NPHAND_THROW_CHECK(common(parts[i].header()) == common(parts.front().header()),
                       "db merge: the shards come from different builds");
    NPHAND_THROW_CHECK(shard["index"].get<int>() == i && shard["count"].get<int>() == count &&
                           shard["begin"].get<uint64_t>() == next,
                       "db merge: shard ", i, " of ", count, " is missing or repeated");
    next = shard["end"].get<uint64_t>();
  }
  nlohmann::json header = common(parts.front().header());
  NPHAND_THROW_CHECK(next == header["total_entries"].get<uint64_t>(), "db merge: the shards do not cover the build");
  header["entries"] = next;
  // Key order as an unsharded build writes it (nlohmann::json sorts keys, so this matches).
  DatabaseWriter writer(path, header, DatabaseWriter::Mode::kFresh);
  try {
    for (const Database& part : parts) writer.Append(part.Records(0, part.size()));
    writer.Finish();
  } catch (const Error&) {
    writer.Discard();
    throw;
  }
}

nlohmann::json DescribeDatabase(const Database& db) {
  uint64_t with_object = 0, no_hand = 0;
  std::set<int> grasps, gestures, steps, viewpoints;
  for (size_t i = 0; i < db.size(); ++i) {
    const EntryMeta meta = db.Meta(i);
    with_object += meta.with_object;
    no_hand += !meta.has_hand;
    (IsGesture(meta.grasp) ? gestures : grasps).insert(meta.grasp);
    steps.insert(meta.step);
    viewpoints.insert(meta.viewpoint);
  }
  const nlohmann::json& header = db.header();
  nlohmann::json info = {
      {"entries", db.size()},
      {"grasps", grasps.size()},
      {"gestures", gestures.size()},
      {"steps", steps.size()},
      {"viewpoints", viewpoints.size()},
      {"with_object", with_object},
      {"without_object", db.size() - with_object},
      {"no_hand", no_hand},
      {"features",
       {{{"name", header["hog"]["name"]}, {"dimension", header["hog"]["dimension"]}},
        {{"name", "crop_bits"}, {"dimension", kCropBitsSide * kCropBitsSide}}}},
      {"record_bytes", db.layout().RecordBytes()},
      {"file_bytes", db.file_bytes()},
      {"render", header["render"]},
      {"crop", header["crop"]},
      {"normalize_roll", header["hog"].value("normalize_roll", false)},
  };
  // Files from before the coverage was stored in the header have it measured here.
  const nlohmann::json coverage =
      header.contains("view_sphere_coverage") ? header["view_sphere_coverage"] : CoverageJson(header["viewpoints"].get<int>());
  info["view_sphere"] = {{"directions", header["viewpoints"]},
                         {"max_neighbour_deg", coverage["max_neighbour_deg"]},
                         {"covering_radius_deg", coverage["covering_radius_deg"]}};
  if (header.contains("shard")) info["shard"] = header["shard"];
  return info;
}

}  // namespace nphand

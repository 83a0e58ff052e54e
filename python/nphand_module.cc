// The Python module `nphand`: the library's database, index, hand model, renderer, rendered
// sequences and estimator, with numpy arrays in and out. nphand::Error arrives as
// nphand.Error (a RuntimeError) with the message the CLI prints; the long calls (building a
// database, estimating a frame, rendering) release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "apps/frame_source.h"
#include "apps/video_file.h"
#include "nphand/db/builder.h"
#include "nphand/db/database.h"
#include "nphand/estimate/estimator.h"
#include "nphand/index/backends.h"
#include "nphand/model/hand_model.h"
#include "nphand/render/draw.h"
#include "nphand/render/renderer.h"
#include "nphand/scene/gesture.h"
#include "nphand/scene/grasp.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/sequence/sequence.h"
#include "nphand/util/check.h"
#include "nphand/util/version.h"

namespace py = pybind11;

namespace nphand {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

// Copies of the library's values as numpy arrays.
py::array_t<double> Points3(const Keypoints3d& points) {
  py::array_t<double> out({kNumKeypoints, 3});
  auto view = out.mutable_unchecked<2>();
  for (int k = 0; k < kNumKeypoints; ++k) {
    for (int a = 0; a < 3; ++a) view(k, a) = points[k][a];
  }
  return out;
}

py::array_t<double> Points2(const std::array<Eigen::Vector2d, kNumKeypoints>& points) {
  py::array_t<double> out({kNumKeypoints, 2});
  auto view = out.mutable_unchecked<2>();
  for (int k = 0; k < kNumKeypoints; ++k) {
    view(k, 0) = points[k].x();
    view(k, 1) = points[k].y();
  }
  return out;
}

py::array_t<double> Matrix3(const Eigen::Matrix3d& m) {
  py::array_t<double> out({3, 3});
  auto view = out.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) view(r, c) = m(r, c);
  }
  return out;
}

py::array_t<double> Angles(const JointAngles& angles) {
  py::array_t<double> out(kNumDofs);
  std::memcpy(out.mutable_data(), angles.data(), sizeof(double) * kNumDofs);
  return out;
}

JointAngles AnglesFrom(const py::array_t<double, py::array::c_style | py::array::forcecast>& array) {
  NPHAND_THROW_CHECK(array.ndim() == 1 && array.shape(0) == kNumDofs, "angles: expected ", kNumDofs,
                     " joint angles in radians");
  JointAngles angles;
  std::memcpy(angles.data(), array.data(), sizeof(double) * kNumDofs);
  return angles;
}

py::array MatArray(const cv::Mat& mat) {
  std::vector<py::ssize_t> shape = {mat.rows, mat.cols};
  if (mat.channels() > 1) shape.push_back(mat.channels());
  const size_t row = mat.cols * mat.elemSize();
  py::array out;
  switch (mat.depth()) {
    case CV_8U: out = py::array_t<uint8_t>(shape); break;
    case CV_32F: out = py::array_t<float>(shape); break;
    default: NPHAND_CHECK(false, "unexpected image depth ", mat.depth());
  }
  auto* data = static_cast<uint8_t*>(out.mutable_data());
  for (int r = 0; r < mat.rows; ++r) std::memcpy(data + r * row, mat.ptr(r), row);
  return out;
}

using BgrArray = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;

// A header over the caller's BGR pixels (no copy): valid while `frame` lives.
cv::Mat FrameMat(const BgrArray& frame) {
  if (frame.ndim() != 3 || frame.shape(2) != 3) {
    std::ostringstream message;
    message << "a frame is an H x W x 3 uint8 BGR image (as cv2.imread gives), not ";
    if (frame.ndim() == 0) message << "a scalar";
    for (py::ssize_t d = 0; d < frame.ndim(); ++d) message << (d > 0 ? " x " : "") << frame.shape(d);
    throw py::value_error(message.str());
  }
  return cv::Mat(static_cast<int>(frame.shape(0)), static_cast<int>(frame.shape(1)), CV_8UC3,
                 const_cast<uint8_t*>(frame.data()));
}

// A copy of the caller's frame with 21 keypoints (21 x 2 pixels) drawn as a skeleton.
py::array Drawn(const BgrArray& frame, const py::array_t<double, py::array::c_style | py::array::forcecast>& keypoints) {
  NPHAND_THROW_CHECK(keypoints.ndim() == 2 && keypoints.shape(0) == kNumKeypoints && keypoints.shape(1) == 2,
                     "draw: the keypoints are 21 x 2 pixels");
  cv::Mat picture = FrameMat(frame).clone();
  std::array<Eigen::Vector2d, kNumKeypoints> points;
  for (int k = 0; k < kNumKeypoints; ++k) points[k] = Eigen::Vector2d(keypoints.at(k, 0), keypoints.at(k, 1));
  DrawKeypoints2d(points, &picture);
  return MatArray(picture);
}

// The database, index and hand model an estimator reads, kept alive by it.
class Estimate {
 public:
  Estimate(std::shared_ptr<const Database> db, std::shared_ptr<const KnnIndex> index,
           std::shared_ptr<const HandModel> hand, const EstimatorOptions& options)
      : db_(std::move(db)), index_(std::move(index)), hand_(std::move(hand)),
        estimator_(std::make_unique<Estimator>(*db_, *index_, *hand_, options)) {}

  FrameResult Process(const BgrArray& frame, std::optional<double> time_s, std::optional<std::array<int, 4>> roi) {
    const cv::Mat bgr = FrameMat(frame);
    const double t = time_s.value_or(next_time_);
    std::optional<cv::Rect> box;
    if (roi.has_value()) {
      const auto [x, y, width, height] = *roi;
      NPHAND_THROW_CHECK(width > 0 && height > 0, "estimator: roi is (x, y, width, height) in pixels, with a width and height above 0");
      box = cv::Rect(x, y, width, height);
    }
    FrameResult result;
    {
      py::gil_scoped_release release;
      result = estimator_->Process(bgr, t, box);
    }
    next_time_ = t + 1.0 / 30.0;
    return result;
  }
  void Reset() {
    estimator_->Reset();
    next_time_ = 0.0;
  }

 private:
  std::shared_ptr<const Database> db_;
  std::shared_ptr<const KnnIndex> index_;
  std::shared_ptr<const HandModel> hand_;
  std::unique_ptr<Estimator> estimator_;
  double next_time_ = 0.0;
};

py::dict SceneImages(const HandModel& hand, const Scene& scene, const Intrinsics& intrinsics) {
  RenderedImages images;
  {
    py::gil_scoped_release release;
    Renderer renderer(hand);
    images = renderer.Render(scene, intrinsics);
  }
  Keypoints3d keypoints = hand.KeypointsOf(scene.hand);
  std::array<Eigen::Vector2d, kNumKeypoints> pixels;
  for (int k = 0; k < kNumKeypoints; ++k) {
    keypoints[k] += scene.wrist_in_camera;
    pixels[k] = Project(intrinsics, keypoints[k]);
  }
  py::dict out;
  out["rgb"] = MatArray(images.rgb);
  out["labels"] = MatArray(images.labels);
  out["depth"] = MatArray(images.depth);
  out["keypoints_2d"] = Points2(pixels);
  out["keypoints_3d"] = Points3(keypoints);
  out["rotation"] = Matrix3(scene.hand.camera_from_hand);
  out["angles"] = Angles(scene.hand.angles);
  return out;
}

}  // namespace
}  // namespace nphand

PYBIND11_MODULE(nphand, m) {
  using namespace nphand;
  m.doc() = "nphand: 3D hand pose from monocular RGB, with object context (Romero et al. 2013), on a CPU";
  m.attr("__version__") = kVersion;
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);

  std::vector<std::string> keypoint_names, dof_names;
  for (int k = 0; k < kNumKeypoints; ++k) keypoint_names.push_back(KeypointName(k));
  for (const DofInfo& dof : Dofs()) dof_names.push_back(dof.name);
  m.attr("KEYPOINT_NAMES") = keypoint_names;
  m.attr("DOF_NAMES") = dof_names;
  m.def("default_asset_dir", [] { return DefaultAssetDir(); },
        "Where the hand mesh is looked for: $NPHAND_ASSET_DIR, else share/nphand/hand above this module");
  m.def("articulation", [](const std::string& name) { return Angles(NamedArticulation(name)); }, py::arg("name"),
        "Joint angles (radians) of a named articulation: rest, relaxed, fist, point, pinch");

  py::class_<HandModel, std::shared_ptr<HandModel>>(m, "HandModel", "The rigged generic-hand mesh")
      .def(py::init([](const std::string& hand, std::optional<std::filesystem::path> asset_dir) {
             return std::make_shared<HandModel>(
                 HandModel::Load(HandednessFromString(hand), asset_dir.value_or(DefaultAssetDir())));
           }),
           py::arg("hand") = "right", py::arg("asset_dir") = py::none())
      .def_property_readonly("hand", [](const HandModel& h) { return ToString(h.handedness()); })
      .def_property_readonly("vertex_count", [](const HandModel& h) { return h.bind_vertices().size(); })
      .def(
          "keypoints",
          [](const HandModel& h, const py::array_t<double, py::array::c_style | py::array::forcecast>& rotation,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& angles) {
            NPHAND_THROW_CHECK(rotation.ndim() == 2 && rotation.shape(0) == 3 && rotation.shape(1) == 3,
                               "keypoints: the rotation is a 3 x 3 matrix");
            HandPose pose;
            pose.handedness = h.handedness();
            pose.camera_from_hand = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation.data());
            pose.angles = AnglesFrom(angles);
            return Points3(h.KeypointsOf(pose));
          },
          py::arg("rotation"), py::arg("angles"),
          "The 21 keypoints (metres, camera orientation, wrist at the origin) of a pose");

  m.def(
      "render",
      [](const HandModel& hand, py::object angles, const std::string& grasp, int step, double azimuth, double elevation,
         double roll, double distance, int width, int height, double fov) {
        Scene scene;
        scene.hand.handedness = hand.handedness();
        scene.hand.camera_from_hand =
            CameraFromHand(Viewpoint{azimuth * kRadPerDeg, elevation * kRadPerDeg, roll * kRadPerDeg});
        if (!grasp.empty()) {
          NPHAND_THROW_CHECK(step >= 0 && step < kGraspSteps, "render: step must be between 0 and ", kGraspSteps - 1);
          const Grasp g = MakeGrasp(hand, GraspByName(grasp));
          scene.hand.angles = g.steps[step];
          scene.objects = {g.object};
        } else if (py::isinstance<py::str>(angles)) {
          scene.hand.angles = NamedArticulation(angles.cast<std::string>());
        } else {
          scene.hand.angles = AnglesFrom(angles.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>());
        }
        scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, hand.bind_centre(), distance);
        const Intrinsics intrinsics = Intrinsics::FromFieldOfView(width, height, fov * kRadPerDeg);
        std::string why;
        NPHAND_THROW_CHECK(intrinsics.Check(&why), "render: ", why);
        return SceneImages(hand, scene, intrinsics);
      },
      py::arg("hand"), py::arg("angles") = "rest", py::arg("grasp") = "", py::arg("step") = kGraspSteps - 1,
      py::arg("azimuth") = 0.0, py::arg("elevation") = 0.0, py::arg("roll") = 0.0, py::arg("distance") = 0.45,
      py::arg("width") = 320, py::arg("height") = 240, py::arg("fov") = 60.0,
      "Renders the hand (a named articulation, 21 angles in radians, or a grasp of the taxonomy with its object) "
      "from a viewpoint in degrees: a dict of rgb (BGR), labels, depth (metres), keypoints_2d (pixels), "
      "keypoints_3d (camera frame, metres), rotation, angles");

  m.def(
      "build_database",
      [](const HandModel& hand, const std::filesystem::path& path, std::vector<int> grasps,
         const std::vector<std::string>& gestures, int directions, int image_size, int threads) {
        DatabaseBuildOptions options;
        options.grasps = std::move(grasps);
        options.gestures = GestureIdsNamed(gestures, "build_database: gestures");
        options.directions = directions;
        options.image_size = image_size;
        options.threads = threads;
        py::gil_scoped_release release;
        return BuildDatabase(hand, options, path, nullptr).entries;
      },
      py::arg("hand"), py::arg("path"), py::arg("grasps") = std::vector<int>{},
      py::arg("gestures") = std::vector<std::string>{"all"}, py::arg("directions") = 648, py::arg("image_size") = 128,
      py::arg("threads") = 0,
      "Builds a database file (atomically; resumable) and returns its entry count; grasps empty: all 33; gestures: "
      "names, ['all'] (the default), ['none'] or [] for none");

  py::class_<Database, std::shared_ptr<Database>>(m, "Database", "A database file of (pose, descriptor) entries")
      .def(py::init([](const std::filesystem::path& path) { return std::make_shared<Database>(Database::Open(path)); }),
           py::arg("path"))
      .def("__len__", &Database::size);

  py::class_<KnnIndex, std::shared_ptr<KnnIndex>>(m, "Index", "Nearest-neighbour search over a database")
      .def(py::init([](const std::shared_ptr<Database>& db, const std::filesystem::path& path) {
             return std::shared_ptr<KnnIndex>(LoadIndex(path, *db));
           }),
           py::arg("db"), py::arg("path"), py::keep_alive<1, 2>(),
           "Loads an index file made for `db` (nphand index build); the index keeps `db` alive")
      .def_static(
          "build",
          [](const std::shared_ptr<Database>& db, const std::string& backend) {
            IndexOptions options = backend == "exact" ? IndexOptions::Exact() : IndexOptions{};
            options.backend = backend;
            std::string why;
            NPHAND_THROW_CHECK(options.Check(&why), "index: ", why);
            py::gil_scoped_release release;
            return std::shared_ptr<KnnIndex>(BuildIndex(*db, options));
          },
          py::arg("db"), py::arg("backend") = "hnswlib-sq8", py::keep_alive<0, 1>(),
          "Builds an index of `db` in memory; the index keeps `db` alive")
      .def(
          "save", [](const KnnIndex& index, const std::filesystem::path& path, const Database& db) { index.Save(path, db); },
          py::arg("path"), py::arg("db"), "Writes the index file (atomically) for the database it was built from")
      .def_property_readonly("backend", &KnnIndex::Backend);

  py::class_<FrameResult>(m, "Result", "One frame's estimate")
      .def_property_readonly("detected", &FrameResult::detected)
      .def_property_readonly("status", [](const FrameResult& r) { return ToString(r.status); })
      .def_readonly("reason", &FrameResult::reason)
      .def_readonly("frame", &FrameResult::frame)
      .def_property_readonly("hand", [](const FrameResult& r) { return ToString(r.hand); })
      .def_property_readonly("keypoints_2d", [](const FrameResult& r) { return Points2(r.keypoints_2d); },
                             "21 x 2, pixels (pixel centres at +0.5)")
      .def_property_readonly("keypoints_3d", [](const FrameResult& r) { return Points3(r.keypoints_camera); },
                             "21 x 3, metres, camera frame")
      .def_property_readonly("keypoints_hand", [](const FrameResult& r) { return Points3(r.keypoints_hand); },
                             "21 x 3, metres, camera orientation, wrist at the origin")
      .def_property_readonly("rotation", [](const FrameResult& r) { return Matrix3(r.pose.camera_from_hand); },
                             "3 x 3, the hand frame into the camera frame")
      .def_property_readonly("angles", [](const FrameResult& r) { return Angles(r.pose.angles); },
                             "21 joint angles, radians (nphand.DOF_NAMES)")
      .def_property_readonly("box", [](const FrameResult& r) { return py::make_tuple(r.box.x, r.box.y, r.box.width, r.box.height); })
      .def_readonly("depth_m", &FrameResult::depth_m)
      .def_readonly("confidence", &FrameResult::confidence)
      .def_readonly("mean_of", &FrameResult::mean_of, "hypotheses averaged into the estimate (1: the best alone)")
      .def_readonly("refined", &FrameResult::refined, "with refine: whether the refinement moved the pose")
      .def_property_readonly(
          "proportions",
          [](const FrameResult& r) -> py::object {
            if (!r.proportions.has_value()) return py::none();
            py::dict d;
            d["length"] = r.proportions->length;
            d["width"] = r.proportions->width;
            d["held"] = r.proportions->held;
            return d;
          },
          "with refine_move holding \"proportions\": {length, width, held}, the hand's as factors of the database "
          "hand's; else None")
      .def_readonly("grasps", &FrameResult::grasps)
      .def_readonly("objects", &FrameResult::objects)
      .def_property_readonly("ms", [](const FrameResult& r) { return r.ms.total; }, "the estimator's time on the frame");

  py::class_<Estimate>(m, "Estimator", "Hand poses frame by frame, with the temporal prior over a video")
      .def(py::init([](std::shared_ptr<Database> db, std::shared_ptr<KnnIndex> index, std::shared_ptr<HandModel> hand,
                       const std::string& side, int k, int track_views, bool refine, const std::vector<std::string>& refine_move,
                       bool smooth, double hand_length, double fov, double focal, bool faces, double mode_mean) {
             EstimatorOptions options;
             SetHandChoice(side, &options);
             options.k = k;
             options.track_views = track_views;
             options.refine = refine;
             SetRefineMoves(refine_move, &options.refinement);
             options.smooth = smooth;
             options.hand_length_m = hand_length;
             options.fov_deg = fov;
             options.focal_px = focal;
             if (!faces) options.skin.face_cascade.clear();
             options.mode_mean = mode_mean;
             std::string why;
             NPHAND_THROW_CHECK(options.Check(&why), "estimator: ", why);
             return std::make_unique<Estimate>(std::move(db), std::move(index), std::move(hand), options);
           }),
           py::arg("db"), py::arg("index"), py::arg("hand_model"), py::arg("hand") = "right", py::arg("k") = 500,
           py::arg("track_views") = EstimatorOptions{}.track_views, py::arg("refine") = false,
           py::arg("refine_move") = RefineMoves(RefineOptions{}), py::arg("smooth") = true,
           py::arg("hand_length") = 0.18, py::arg("fov") = 60.0,
           py::arg("focal") = 0.0, py::arg("faces") = true, py::arg("mode_mean") = EstimatorOptions{}.mode_mean)
      .def("process", &Estimate::Process, py::arg("frame"), py::arg("time_s") = py::none(), py::arg("roi") = py::none(),
           "Estimates the hand in the next frame (H x W x 3 uint8 BGR); time_s defaults to 1/30 s after the last; "
           "roi (x, y, width, height), e.g. from your own hand detector, confines the search to that box")
      .def("reset", &Estimate::Reset, "Forgets the track (a new video)");

  m.def("draw", &Drawn, py::arg("frame"), py::arg("keypoints_2d"),
        "A copy of the BGR frame with the 21 keypoints (pixels) drawn as a skeleton");

  py::class_<FrameSource>(m, "FrameSource",
                          "Frames of a video file, an image folder (name order) or a camera index, as nphand estimate reads "
                          "them; iterating gives dicts of frame (BGR, or None if unreadable), time_s, error, name")
      .def(py::init<const std::string&, double>(), py::arg("input"), py::arg("fps") = 30.0)
      .def_property_readonly("fps", &FrameSource::fps)
      .def_property_readonly("count", &FrameSource::count)
      .def_property_readonly("kind", &FrameSource::kind)
      .def("__iter__", [](FrameSource& source) -> FrameSource& { return source; })
      .def("__next__", [](FrameSource& source) {
        std::optional<Frame> frame;
        {
          py::gil_scoped_release release;
          frame = source.Next();
        }
        if (!frame.has_value()) throw py::stop_iteration();
        py::dict out;
        out["frame"] = frame->error.empty() ? py::object(MatArray(frame->bgr)) : py::none();
        out["time_s"] = frame->time_s;
        out["error"] = frame->error;
        out["name"] = frame->name;
        return out;
      });

  py::class_<VideoFile>(m, "VideoWriter",
                        "An MPEG-4 video written as nphand writes its overlays: under a partial name, checked and "
                        "renamed by finish()")
      .def(py::init<const std::filesystem::path&, double>(), py::arg("path"), py::arg("fps"))
      .def("write", [](VideoFile& video, const BgrArray& frame) { video.Write(FrameMat(frame)); }, py::arg("frame"))
      .def("finish", &VideoFile::Finish)
      .def_property_readonly("frames", &VideoFile::frames);

  py::class_<Sequence>(m, "Sequence", "A rendered grasping sequence with ground truth (nphand sequence)")
      .def(py::init([](std::shared_ptr<HandModel> hand, int grasp, int frames, double object_scale,
                       const std::string& background, bool face, const std::string& forearm, uint64_t seed) {
             SequenceOptions options;
             options.grasp = grasp;
             options.frames = frames;
             options.object_scale = object_scale;
             options.background = BackgroundKindFromString(background);
             options.face = face;
             options.forearm = ForearmKindFromString(forearm);
             options.hand = hand->handedness();
             options.seed = seed;
             return std::make_unique<Sequence>(*hand, options);
           }),
           py::arg("hand_model"), py::arg("grasp") = 1, py::arg("frames") = 30, py::arg("object_scale") = 0.8,
           py::arg("background") = "texture", py::arg("face") = false, py::arg("forearm") = "bare", py::arg("seed") = 1,
           py::keep_alive<1, 2>())
      .def("__len__", &Sequence::size)
      .def_property_readonly("hand_length", &Sequence::hand_length_m)
      .def(
          "render",
          [](Sequence& sequence, int i) {
            NPHAND_THROW_CHECK(i >= 0 && i < sequence.size(), "sequence: frame ", i, " is not in 0..",
                               sequence.size() - 1);
            SequenceFrame frame;
            {
              py::gil_scoped_release release;
              frame = sequence.Render(i);
            }
            Keypoints3d camera = frame.keypoints;
            for (Eigen::Vector3d& k : camera) k += frame.wrist_in_camera;
            py::dict out;
            out["rgb"] = MatArray(frame.rgb);
            out["time_s"] = frame.time_s;
            out["keypoints_2d"] = Points2(frame.keypoints_2d);
            out["keypoints_3d"] = Points3(camera);
            out["rotation"] = Matrix3(frame.pose.camera_from_hand);
            out["angles"] = Angles(frame.pose.angles);
            return out;
          },
          py::arg("i"), "Frame i: a dict of rgb (BGR), time_s and the truth (keypoints_2d, keypoints_3d, rotation, angles)");
}

// What `nphand estimate` and the commands around it do with their files when things go
// wrong: an output that is an input, two runs into one output, stop signals, a full disk, a
// truncated video, images that cannot be read. Each case was a reproducer of issue 17 and
// failed before its fix. Signals, the full disk and the second run are real: a child
// process runs the nphand binary.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "apps/db_command.h"
#include "apps/estimate_command.h"
#include "apps/eval_command.h"
#include "apps/index_command.h"
#include "apps/sequence_command.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "tests/apps/command_fixture.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

constexpr size_t kLongFrames = 600;

std::string Text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Every line of a JSON-lines file, each parsed (a cut-off line fails the test).
std::vector<nlohmann::json> Lines(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(Text(path));
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json json = nlohmann::json::parse(line, nullptr, false);
    EXPECT_FALSE(json.is_discarded()) << path << ": line " << lines.size() + 1 << " is not whole";
    lines.push_back(json);
  }
  const std::string text = Text(path);
  EXPECT_TRUE(text.empty() || text.back() == '\n') << path << " ends inside a line";
  return lines;
}

size_t LineCount(const std::filesystem::path& path) {
  const std::string text = Text(path);
  return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
}

int VideoFrames(const std::filesystem::path& path) {
  cv::VideoCapture video(path.string(), cv::CAP_FFMPEG);
  return video.isOpened() ? static_cast<int>(video.get(cv::CAP_PROP_FRAME_COUNT)) : -1;
}

// The nphand binary run in a child process, its output and errors in files; `file_limit`
// (bytes) makes writes beyond it fail as on a full disk.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::filesystem::path& dir, rlim_t file_limit = RLIM_INFINITY)
      : out_(dir / "child.out"), err_(dir / "child.err") {
    // Everything is made before the fork: between fork and exec the child of a threaded
    // process may only make async-signal-safe calls (no allocation).
    std::vector<char*> argv = {const_cast<char*>(NPHAND_BINARY)};
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int err = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    rlimit limit;
    limit.rlim_cur = limit.rlim_max = file_limit;
    pid_ = ::fork();
    if (pid_ != 0) {
      ::close(out);
      ::close(err);
      return;
    }
    ::dup2(out, 1);
    ::dup2(err, 2);
    if (file_limit != RLIM_INFINITY) {
      ::signal(SIGXFSZ, SIG_IGN);
      ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ::execv(NPHAND_BINARY, argv.data());
    ::_exit(127);
  }
  ~Child() {
    if (!waited_) {
      ::kill(pid_, SIGKILL);
      Wait();
    }
  }
  void Signal(int signal) const { ASSERT_EQ(::kill(pid_, signal), 0); }
  // The exit status, or 1000 + the signal that killed it.
  int Wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    waited_ = true;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
  }
  std::string Out() const { return Text(out_); }
  std::string Err() const { return Text(err_); }

 private:
  pid_t pid_ = -1;
  bool waited_ = false;
  std::filesystem::path out_, err_;
};

// Waits (at most a minute) until `path` holds at least `lines` lines.
bool WaitForLines(const std::filesystem::path& path, size_t lines) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (std::chrono::steady_clock::now() < end) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && LineCount(path) >= lines) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

class EstimateHardeningTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(testing::MakeCommandFixture("nphand_estimate_hardening", 24));
    std::filesystem::create_directories(LongInput());
    for (size_t i = 0; i < kLongFrames; ++i) {
      std::filesystem::create_hard_link(Frames() / cv::format("%06zu.png", i % 24), LongInput() / cv::format("%06zu.png", i));
    }
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static std::filesystem::path Db() { return *dir_ / "tiny.db"; }
  // The sequence's frames again and again, for runs long enough to be stopped midway.
  static std::filesystem::path LongInput() { return *dir_ / "long"; }
  static std::filesystem::path Frames() { return *dir_ / "sequence" / "frames"; }
  static EstimateCommandOptions Options(const std::filesystem::path& out) {
    EstimateCommandOptions options;
    options.db = Db();
    options.input = Frames().string();
    options.out = out;
    options.faces = false;
    options.estimator.k = 40;
    options.estimator.max_distance = 2.0;  // the tiny database's views are far apart
    return options;
  }
  // The command line of Options(out).
  static std::vector<std::string> Args(const std::filesystem::path& out, const std::string& input = Frames().string()) {
    return {"estimate", "--db", Db().string(), "--input", input, "--out", out.string(), "--no-faces", "--k", "40",
            "--max-distance", "2"};
  }
  static inline std::filesystem::path* dir_ = nullptr;
};

// Bug 1: an output path destroyed the database, the index or the input, with exit 0.
TEST_F(EstimateHardeningTest, AnOutputThatIsAnInputIsRefusedAndTheInputKept) {
  const auto dir = testing::ScratchDir();
  const std::string db_bytes = Text(Db()), index_bytes = Text(Db().string() + ".idx");
  const std::filesystem::path video = *dir_ / "sequence" / "video.mp4";
  const std::string video_bytes = Text(video);
  std::filesystem::create_symlink(Db(), dir / "linked.db");
  std::filesystem::create_symlink(Db().string() + ".idx", dir / "linked.db.idx");
  std::filesystem::create_directories(dir / "x");
  const auto refused = [&](EstimateCommandOptions options, const std::string& needle) {
    testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, needle);
  };
  EstimateCommandOptions options = Options(Db());
  refused(options, "--out '" + Db().string() + "' is --db");
  options.out = dir / "x" / ".." / "x" / "." / ".." / ".." / ".." / Db().parent_path().filename() / "tiny.db";
  refused(options, "writing it would destroy an input");
  options = Options(Db());
  options.db = dir / "linked.db";
  refused(options, "is --db '" + (dir / "linked.db").string() + "'");
  // Named as a clash even when the database's default index is missing.
  std::filesystem::create_symlink(Db(), dir / "unindexed.db");
  options.db = dir / "unindexed.db";
  refused(options, "is --db '" + (dir / "unindexed.db").string() + "'");
  options = Options(dir / "poses.jsonl");
  options.overlay = Db();
  refused(options, "--overlay '" + Db().string() + "' is --db");
  options = Options(Db().string() + ".idx");
  refused(options, "is --index");
  options = Options(video);
  options.input = video.string();
  refused(options, "is --input");
  options = Options(Frames() / "000003.png");
  refused(options, "is an image of --input");
  options = Options(dir / "both.mp4");
  options.overlay = dir / "x" / ".." / "both.mp4";
  refused(options, "are the same file: one output would overwrite the other");
  IndexBuildCommandOptions index;
  index.db = Db();
  index.out = dir / "linked.db";
  index.index = IndexOptions::Exact();
  testing::ExpectError([&] { RunIndexBuild(index); }, "index build --out '" + (dir / "linked.db").string() + "' is --db");
  testing::ExpectError([&] { RunDbMerge({Db()}, Db()); }, "db merge --out '" + Db().string() + "' is a shard");
  EvalPosesCommandOptions eval;
  eval.truth = *dir_ / "sequence" / "truth.jsonl";
  eval.poses = dir / "x" / "errors.json";
  eval.out_dir = dir / "x";
  WriteFileAtomic(eval.poses, std::string("{}\n"));
  testing::ExpectError([&] { RunEvalPoses(eval); }, "--out '" + eval.poses.string() + "' is --poses");
  // Nothing was touched, and nothing was left behind.
  EXPECT_EQ(Text(Db()), db_bytes);
  EXPECT_EQ(Text(Db().string() + ".idx"), index_bytes);
  EXPECT_EQ(Text(video), video_bytes);
  EXPECT_EQ(Text(eval.poses), "{}\n");
  for (const auto& item : std::filesystem::directory_iterator(*dir_)) {
    EXPECT_EQ(item.path().string().find(".partial"), std::string::npos) << item.path();
  }
}

// Bug 2: a second run into the same --out interleaved its lines with the first's.
TEST_F(EstimateHardeningTest, ASecondRunIntoTheSameOutputsIsRefusedAndTheFirstFinishes) {
  const auto dir = testing::ScratchDir();
  const std::filesystem::path out = dir / "s.jsonl";
  std::vector<std::string> args = Args(out, LongInput().string());
  args.insert(args.end(), {"--overlay", (dir / "o.mp4").string()});
  Child first(args, dir);
  ASSERT_TRUE(WaitForLines(out.string() + ".partial", 1)) << first.Err();
  first.Signal(SIGSTOP);  // holds it mid-run, its files open and locked
  testing::ExpectError([&] { RunEstimate(Options(out), nullptr, nullptr); },
                       "s.jsonl.partial: another nphand process is writing it");
  EstimateCommandOptions same_overlay = Options(dir / "other.jsonl");
  same_overlay.overlay = dir / "o.mp4";
  testing::ExpectError([&] { RunEstimate(same_overlay, nullptr, nullptr); },
                       "o.mp4.partial.mp4: another nphand process is writing it");
  EXPECT_FALSE(std::filesystem::exists(dir / "other.jsonl.partial")) << "the refused run leaves nothing";
  first.Signal(SIGCONT);
  EXPECT_EQ(first.Wait(), 0) << first.Err();
  const std::vector<nlohmann::json> lines = Lines(out);
  ASSERT_EQ(lines.size(), kLongFrames);
  for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i]["frame"], i);
  EXPECT_EQ(VideoFrames(dir / "o.mp4"), static_cast<int>(kLongFrames));
}

// Bugs 3 and 4: SIGTERM and SIGHUP left unrenamed partial files and an unplayable video;
// Ctrl-C exited 0 as if the run were complete.
TEST_F(EstimateHardeningTest, AStopSignalEndsTheRunWithWholeFilesAndSaysSoInItsStatus) {
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(SignalName(signal));
    const auto dir = testing::ScratchDir() / SignalName(signal);
    std::filesystem::create_directories(dir);
    std::vector<std::string> args = Args(dir / "poses.jsonl", LongInput().string());
    args.insert(args.end(), {"--overlay", (dir / "overlay.mp4").string()});
    Child child(args, dir);
    ASSERT_TRUE(WaitForLines(dir / "poses.jsonl.partial", 2)) << child.Err();
    child.Signal(signal);
    EXPECT_EQ(child.Wait(), 128 + signal) << child.Err();
    const nlohmann::json summary = nlohmann::json::parse(child.Out());
    EXPECT_TRUE(summary["stopped"].get<bool>());
    EXPECT_EQ(summary["signal"], SignalName(signal));
    EXPECT_NE(child.Err().find(std::string("stopped by ") + SignalName(signal)), std::string::npos) << child.Err();
    const std::vector<nlohmann::json> lines = Lines(dir / "poses.jsonl");
    EXPECT_EQ(lines.size(), summary["frames"].get<size_t>());
    EXPECT_GE(lines.size(), 2u);
    EXPECT_LT(lines.size(), kLongFrames);
    EXPECT_EQ(VideoFrames(dir / "overlay.mp4"), static_cast<int>(lines.size())) << "the overlay plays, one frame a line";
    EXPECT_FALSE(std::filesystem::exists(dir / "poses.jsonl.partial"));
    EXPECT_FALSE(std::filesystem::exists(dir / "overlay.mp4.partial.mp4"));
  }
}

// Bugs 5 and 8 (a full disk): the run exited 0 listing an unplayable overlay, and left a
// cut-off last line.
TEST_F(EstimateHardeningTest, AFullDiskFailsTheRunAndKeepsOnlyWholeLines) {
  const auto dir = testing::ScratchDir();
  WriteFileAtomic(dir / "poses.jsonl", std::string("{\"the last run\": true}\n"));
  Child child(Args(dir / "poses.jsonl"), dir, 30000);
  EXPECT_EQ(child.Wait(), 1) << child.Err();
  EXPECT_NE(child.Err().find("poses.jsonl.partial: write failed (File too large)"), std::string::npos) << child.Err();
  EXPECT_NE(child.Err().find("whole lines written are in"), std::string::npos) << child.Err();
  const std::vector<nlohmann::json> kept = Lines(dir / "poses.jsonl.partial");
  EXPECT_GE(kept.size(), 1u);
  EXPECT_LT(kept.size(), 24u);
  EXPECT_EQ(Text(dir / "poses.jsonl"), "{\"the last run\": true}\n") << "the last run's file is not replaced";
}

TEST_F(EstimateHardeningTest, AnOverlayThatCannotBeWrittenWholeFailsTheRunAndIsNotListed) {
  // Large frames: the overlay outgrows the limit long before the poses do.
  const auto dir = testing::ScratchDir();
  SequenceCommandOptions sequence;
  sequence.sequence.frames = 8;
  sequence.sequence.width = 640;
  sequence.sequence.height = 480;
  sequence.sequence.grasp = 1;
  sequence.sequence.noise = 6.0;  // noise makes the video large
  sequence.out_dir = dir / "large";
  RunSequence(sequence, nullptr);
  std::vector<std::string> args = Args(dir / "poses.jsonl", (dir / "large" / "frames").string());
  args.insert(args.end(), {"--overlay", (dir / "overlay.mp4").string()});
  Child child(args, dir, 80000);
  EXPECT_EQ(child.Wait(), 1) << child.Err();
  EXPECT_NE(child.Err().find("overlay.mp4: the video is damaged"), std::string::npos) << child.Err();
  EXPECT_NE(child.Err().find("the poses are complete in"), std::string::npos) << child.Err();
  EXPECT_EQ(Lines(dir / "poses.jsonl").size(), 8u);
  EXPECT_FALSE(std::filesystem::exists(dir / "overlay.mp4"));
  EXPECT_FALSE(std::filesystem::exists(dir / "overlay.mp4.partial.mp4"));
}

// Bug 6: a video cut short ended early with exit 0 and nothing said.
TEST_F(EstimateHardeningTest, ATruncatedVideoIsMarked) {
  const auto dir = testing::ScratchDir();
  // Motion JPEG in AVI: its header counts the frames, and a cut file still plays its start.
  {
    cv::VideoWriter video((dir / "whole.avi").string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30.0,
                          cv::Size(240, 180));
    ASSERT_TRUE(video.isOpened());
    for (int i = 0; i < 24; ++i) video.write(cv::imread((Frames() / cv::format("%06d.png", i)).string()));
  }
  const std::string bytes = Text(dir / "whole.avi");
  WriteFileAtomic(dir / "cut.avi", bytes.substr(0, bytes.size() / 2));
  EstimateCommandOptions options = Options(dir / "poses.jsonl");
  options.input = (dir / "whole.avi").string();
  nlohmann::json summary = RunEstimate(options, nullptr, nullptr);
  EXPECT_TRUE(summary["input_complete"].get<bool>());
  EXPECT_EQ(summary["frames"], 24);
  options.input = (dir / "cut.avi").string();
  std::ostringstream progress;
  summary = RunEstimate(options, &progress, nullptr);
  EXPECT_FALSE(summary["input_complete"].get<bool>());
  EXPECT_EQ(summary["frames_expected"], 24);
  EXPECT_LT(summary["frames"].get<int>(), 24);
  EXPECT_GT(summary["frames"].get<int>(), 0);
  EXPECT_NE(progress.str().find("but its container promised 24: the video is truncated or damaged"), std::string::npos)
      << progress.str();
}

// Bugs 7 and 8: one unreadable image ended the run; a truncated JPEG passed unmarked; a name
// that is not UTF-8 failed unnamed; frames of another size fell out of the overlay.
TEST_F(EstimateHardeningTest, ImagesThatCannotBeReadAreLinesAndTheRunGoesOn) {
  const auto dir = testing::ScratchDir();
  const std::filesystem::path input = dir / "frames \xE9t\xE9";  // a folder name in Latin-1
  std::filesystem::create_directories(input);
  const cv::Mat frame = cv::imread((Frames() / "000003.png").string());
  cv::imwrite((input / "0_good.png").string(), frame);
  WriteFileAtomic(input / "1_garbled.png", std::string("\x89PNG\r\n\x1a\n this is not an image"));
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", frame, jpeg);
  jpeg.resize(jpeg.size() * 6 / 10);
  WriteFileAtomic(input / "2_truncated.jpg", jpeg);
  cv::imwrite((input / "3_caf\xE9.png").string(), frame);
  cv::Mat larger;
  cv::resize(frame, larger, cv::Size(320, 200));
  cv::imwrite((input / "4_larger.png").string(), larger);
  WriteFileAtomic(input / "5_empty.png", std::string());
  // A BMP header promising 60000 x 60000 pixels: OpenCV's decoder throws rather than return
  // an empty image (the fuzzer found it).
  std::string huge = std::string("BM") + std::string(12, '\0');
  huge[10] = 54;
  const uint32_t dib[] = {40, 60000, 60000, 1 | (24u << 16), 0, 0, 0, 0, 0, 0};
  huge.append(reinterpret_cast<const char*>(dib), sizeof(dib));
  huge.append(64, '\0');
  WriteFileAtomic(input / "6_huge.bmp", huge);
  EstimateCommandOptions options = Options(dir / "poses.jsonl");
  options.input = input.string();
  options.overlay = dir / "overlay.mp4";
  const nlohmann::json summary = RunEstimate(options, nullptr, nullptr);
  EXPECT_EQ(summary["frames"], 7);
  EXPECT_EQ(summary["unreadable"], 3);
  EXPECT_EQ(summary["damaged"], 1);
  EXPECT_NE(summary["input"].get<std::string>().find("frames \\xE9t\\xE9"), std::string::npos) << summary["input"];
  const std::vector<nlohmann::json> lines = Lines(options.out);
  ASSERT_EQ(lines.size(), 7u);
  for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i]["frame"], i);
  EXPECT_EQ(lines[1]["status"], "unreadable");
  EXPECT_FALSE(lines[1]["detected"].get<bool>());
  EXPECT_NE(lines[1]["reason"].get<std::string>().find("cannot decode"), std::string::npos) << lines[1];
  EXPECT_EQ(lines[5]["status"], "unreadable");
  EXPECT_NE(lines[5]["reason"].get<std::string>().find("empty"), std::string::npos) << lines[5];
  EXPECT_NE(lines[2]["status"], "unreadable");
  ASSERT_TRUE(lines[2].contains("warnings")) << lines[2];
  EXPECT_NE(lines[2]["warnings"][0].get<std::string>().find("truncated JPEG"), std::string::npos);
  EXPECT_EQ(lines[3]["image"], "3_caf\\xE9.png");
  EXPECT_EQ(lines[6]["status"], "unreadable");
  EXPECT_NE(lines[6]["reason"].get<std::string>().find("cannot decode"), std::string::npos) << lines[6];
  EXPECT_EQ(lines[4]["status"], lines[0]["status"]);
  EXPECT_EQ(VideoFrames(options.overlay), 7) << "one overlay frame a line, whatever the image's size";
}

TEST_F(EstimateHardeningTest, AnOverlayNotNamedMp4IsRefused) {
  EstimateCommandOptions options = Options(testing::ScratchDir() / "poses.jsonl");
  options.overlay = testing::ScratchDir() / "overlay.avi";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "overlay.avi': nphand writes the overlay as MPEG-4");
}

}  // namespace
}  // namespace nphand

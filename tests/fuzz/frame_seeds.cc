// Makes the seeds of the frames fuzz target from a rendered sequence's frames folder and
// video: a selector byte (0 .png, 1 .jpg, 2 .bmp, 3 video), then a real small file.
// Usage: frame_seeds FRAMES_FOLDER VIDEO OUT_FOLDER
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace {

void Write(const std::filesystem::path& path, unsigned char selector, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.put(static_cast<char>(selector));
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<unsigned char> Read(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: frame_seeds FRAMES_FOLDER VIDEO OUT_FOLDER\n");
    return 2;
  }
  const std::filesystem::path frames = argv[1], video = argv[2], out = argv[3];
  std::filesystem::create_directories(out);
  const cv::Mat frame = cv::imread((frames / "000000.png").string());
  if (frame.empty()) {
    std::fprintf(stderr, "frame_seeds: cannot read %s\n", (frames / "000000.png").c_str());
    return 1;
  }
  std::vector<unsigned char> bytes;
  for (const auto& [name, selector, extension] : {std::tuple{"png", 0, ".png"}, {"jpg", 1, ".jpg"}, {"bmp", 2, ".bmp"}}) {
    cv::imencode(extension, frame, bytes);
    Write(out / name, static_cast<unsigned char>(selector), bytes);
  }
  cv::imencode(".jpg", frame, bytes);
  bytes.resize(bytes.size() / 2);
  Write(out / "jpg_truncated", 1, bytes);
  Write(out / "mp4", 3, Read(video));
  const std::filesystem::path avi = out / "tmp.avi";
  {
    cv::VideoWriter writer(avi.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30.0, frame.size());
    for (int i = 0; i < 3; ++i) writer.write(frame);
  }
  Write(out / "avi", 3, Read(avi));
  std::filesystem::remove(avi);
  return 0;
}

#include "nphand/segment/skin.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "nphand/segment/regions.h"
#include "nphand/util/check.h"

namespace nphand {

struct SkinSegmenter::FaceDetector {
  cv::CascadeClassifier cascade;
};

bool SkinOptions::Check(std::string* why) const {
  auto byte = [](int v) { return v >= 0 && v <= 255; };
  if (!byte(cr_min) || !byte(cr_max) || !byte(cb_min) || !byte(cb_max) || !byte(y_min) || cr_min > cr_max ||
      cb_min > cb_max) {
    *why = "skin box bounds must be within 0..255 with min <= max";
  } else if (!byte(rim_cr_min) || !byte(rim_cr_max) || !byte(rim_cb_min) || !byte(rim_cb_max) || rim_cr_min > cr_min ||
             rim_cr_max < cr_max || rim_cb_min > cb_min || rim_cb_max < cb_max) {
    *why = "the skin rim's box must lie within 0..255 and hold the skin box";
  } else if (!(rim_area >= 0.0 && rim_area < 1.0)) {
    *why = "the skin rim's largest piece must be within [0, 1) of the frame";
  } else if (!(learn_rate > 0.0 && learn_rate <= 1.0) || !(keep >= 0.0 && keep <= add && add <= 1.0)) {
    *why = "skin adaptation needs 0 < learn rate <= 1 and 0 <= keep <= add <= 1";
  } else if (bins < 4 || bins > 256 || 256 % bins != 0) {
    *why = "skin histogram bins must divide 256 (4..256)";
  } else if (open_px < 0 || open_px > 31 || close_px < 0 || close_px > 31) {
    *why = "skin morphology sizes must be within 0..31 pixels";
  } else if (!(min_area > 0.0 && min_area < 1.0)) {
    *why = "the smallest skin region must be within (0, 1) of the frame";
  } else if (!(face_chroma >= 0.0 && face_chroma <= 10.0)) {
    *why = "the face's chroma reach must be within 0..10 standard deviations";
  } else if (face_interval < 1 || face_relook < 1) {
    *why = "the face interval and relook must be at least 1 frame";
  } else if (work_width != 0 && work_width < 64) {
    *why = "the working width must be 0 (the frame's) or at least 64 pixels";
  } else {
    return true;
  }
  return false;
}

cv::Mat SkinSegmentation::RegionMask(const SkinRegion& region) const { return Mask({region.label}, region.box); }

SkinSegmenter::SkinSegmenter(const SkinOptions& options) : options_(options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "skin: ", why);
  if (!options.face_cascade.empty()) {
    NPHAND_THROW_CHECK(std::filesystem::is_regular_file(options.face_cascade), options.face_cascade,
                       ": no face cascade there (install Debian's opencv-data, or turn face masking off)");
    detector_ = std::make_shared<FaceDetector>();
    NPHAND_THROW_CHECK(detector_->cascade.load(options.face_cascade), options.face_cascade,
                       ": not a face cascade OpenCV can read");
  }
  Reset();
}

void SkinSegmenter::Reset() {
  hand_hist_ = cv::Mat::zeros(options_.bins, options_.bins, CV_32FC1);
  rest_hist_ = cv::Mat::zeros(options_.bins, options_.bins, CV_32FC1);
  learned_ = 0;
  frames_ = 0;
  face_sized_.clear();
  newcomer_ = false;
  last_look_ = 0;
  faces_.clear();
  face_looks_.clear();
  RebuildLookup();
}

void SkinSegmenter::RebuildLookup() {
  lookup_.create(256, 256, CV_8UC1);
  const int shift = 256 / options_.bins;
  for (int cr = 0; cr < 256; ++cr) {
    for (int cb = 0; cb < 256; ++cb) {
      const bool in_box = cr >= options_.cr_min && cr <= options_.cr_max && cb >= options_.cb_min && cb <= options_.cb_max;
      bool rim = options_.rim_area > 0.0 && !in_box && cr >= options_.rim_cr_min && cr <= options_.rim_cr_max &&
                 cb >= options_.rim_cb_min && cb <= options_.rim_cb_max;
      bool skin = in_box;
      if (learned_ > 0) {
        const float h = hand_hist_.at<float>(cr / shift, cb / shift), r = rest_hist_.at<float>(cr / shift, cb / shift);
        // Chroma neither side has seen stays with the box.
        if (h + r > 1e-5f) {
          const double p = h / (h + r);
          skin = (in_box && p >= options_.keep) || p >= options_.add;
          rim = rim && p >= options_.keep;
        }
      }
      lookup_.at<uint8_t>(cr, cb) = skin ? kSkin : rim ? kRim : 0;
    }
  }
}

namespace {

// `bgr` halved (2 x 2 pixel means) until at most `width` wide (0: as it is); `scale` gets
// the frame's pixels per pixel of the result.
cv::Mat Working(const cv::Mat& bgr, int width, int* scale) {
  cv::Mat work = bgr;
  *scale = 1;
  while (width > 0 && work.cols > width) {
    cv::Mat half;
    cv::resize(work, half, cv::Size((work.cols + 1) / 2, (work.rows + 1) / 2), 0.0, 0.0, cv::INTER_AREA);
    work = half;
    *scale *= 2;
  }
  return work;
}

// By label of `labels` (CV_32SC1, `count` labels): whether any of its pixels is non-zero in
// `mask` (CV_8UC1 of the same size).
std::vector<uint8_t> LabelsMeeting(const cv::Mat& labels, int count, const cv::Mat& mask) {
  std::vector<uint8_t> meets(count, 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    const uint8_t* in = mask.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) meets[label[x]] |= in[x] != 0;
  }
  return meets;
}

// The rim's pieces (`rim`, CV_8UC1, 255 = rim chroma; marked in passing) that meet `skin`
// (8-connected) and cover at most `largest` pixels, added to `skin`. Only the pieces that
// meet skin are visited, each once.
void AddRim(int largest, cv::Mat* rim, cv::Mat* skin) {
  constexpr uint8_t kSeen = 128, kKept = 64;
  cv::Mat seeds;
  cv::dilate(*skin, seeds, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  seeds &= *rim;
  std::vector<cv::Point> at;
  cv::findNonZero(seeds, at);
  if (at.empty()) return;
  for (const cv::Point& p : at) {
    if (rim->at<uint8_t>(p) != 255) continue;  // its piece was visited
    const int area = cv::floodFill(*rim, p, kSeen, nullptr, 0, 0, 8);
    if (area <= largest) cv::floodFill(*rim, p, kKept, nullptr, 0, 0, 8);
  }
  *skin |= *rim == kKept;
}

// In front of a face, skin taken whole where it goes on outside as an arm (a value of
// InFrontOfFaces), for a neck going on into a skin-coloured sweater goes on outside too:
// such skin does not keep a body below the face from being set aside as one.
constexpr uint8_t kInFrontWhole = 128;
// Skin in front of a face is taken whole where the pieces' rule kept less than this share of it.
constexpr double kWholeShare = 0.75;

// Of the skin within the faces' heads (`heads`: 255 within them; all images at the working
// resolution, `bounds` holding the heads), what lies in front of a face: 255 where the skin
// is parted from the skin at a face's centre (the middle half of its box, `centres`) by the
// frame's edges, in pieces of at least `least` pixels or that reach skin outside the
// faces' shapes (`shapes`: heads and necks), and kInFrontWhole where it is taken whole
// (below). A hand over a face shows its outline against it; the face's own edges (eyes,
// mouth, hair line) part smaller pieces of it, a cheek or the brow, which stay the face's.
// An arm or a hand passing the side of a face, within its head's ellipse only in a sliver,
// goes on outside it.
cv::Mat InFrontOfFaces(const cv::Mat& work, const cv::Mat& skin, const cv::Mat& heads, const cv::Mat& shapes,
                       cv::Rect bounds, const std::vector<cv::Rect>& centres, double least) {
  cv::Mat in_front = cv::Mat::zeros(work.size(), CV_8UC1);
  if (bounds.area() == 0 || centres.empty()) return in_front;
  cv::Mat grey, edges;
  cv::cvtColor(work(bounds), grey, cv::COLOR_BGR2GRAY);
  // Low thresholds: an outline of skin against skin has little contrast.
  cv::Canny(grey, edges, 30.0, 60.0);
  cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
  const cv::Mat head_skin = skin(bounds) & heads(bounds);
  cv::Mat pieces = head_skin & ~edges;
  // Gaps in an outline leave narrow bridges between the hand and the face: an opening a
  // twelfth of a face wide breaks them.
  int widest = 0;
  for (const cv::Rect& c : centres) widest = std::max(widest, 2 * c.width);
  const int k = std::max(3, widest / 12) | 1;
  cv::morphologyEx(pieces, pieces, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  cv::Mat labels;
  // 4-connected, not 8: pieces an outline parts that still touch at a corner stay apart.
  const std::vector<RegionStats> piece_stats = LabelRegions(pieces, &labels, 4);
  const int count = static_cast<int>(piece_stats.size());
  if (count <= 1) return in_front;
  // Pixels by label of `of` (`n` labels) within each centre.
  auto in_centres = [&](const cv::Mat& of, int n) {
    std::vector<std::vector<int>> pixels;
    for (const cv::Rect& centre : centres) {
      const cv::Rect at = (centre - bounds.tl()) & cv::Rect(0, 0, bounds.width, bounds.height);
      pixels.emplace_back(n, 0);
      for (int y = at.y; y < at.y + at.height; ++y) {
        const int* label = of.ptr<int>(y);
        for (int x = at.x; x < at.x + at.width; ++x) ++pixels.back()[label[x]];
      }
    }
    return pixels;
  };
  // Each face is the piece with most pixels in its centre.
  std::vector<uint8_t> face(count, 0);
  std::vector<int> face_centre;  // by centre: its face's pixels there
  for (const std::vector<int>& pixels : in_centres(labels, count)) {
    const auto most = std::max_element(pixels.begin() + 1, pixels.end());
    if (*most > 0) face[most - pixels.begin()] = 1;
    face_centre.push_back(*most);
  }
  // The pieces that reach skin outside the shapes, over what the edges and the opening
  // took from their ends.
  const cv::Mat grow = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k + 2, k + 2));
  cv::Mat outside = skin(bounds) & ~shapes(bounds);
  cv::dilate(outside, outside, grow);
  const std::vector<uint8_t> goes_on = LabelsMeeting(labels, count, outside);
  cv::Mat kept = cv::Mat::zeros(labels.size(), CV_8UC1), face_pieces = cv::Mat::zeros(labels.size(), CV_8UC1);
  for (int y = 0; y < labels.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    uint8_t* keep = kept.ptr<uint8_t>(y);
    uint8_t* of_face = face_pieces.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (label[x] == 0) continue;
      const bool small = piece_stats[label[x]].area < least && goes_on[label[x]] == 0;
      (face[label[x]] != 0 || small ? of_face : keep)[x] = 255;
    }
  }
  // The kept pieces grown back over what the edges and the opening took from them, short
  // of the face's own pieces; and on through the skin the edges do not part from them
  // (fingers thinner than the opening, a textured hand's own creases), short of the face's
  // pieces grown over what the opening took from their borders.
  cv::Mat face_zone, reach_labels;
  cv::dilate(face_pieces, face_zone, grow);
  const cv::Mat reach = head_skin & ~edges & ~face_zone;
  const int reaches = cv::connectedComponents(reach, reach_labels, 4, CV_32S);
  std::vector<uint8_t> joined = LabelsMeeting(reach_labels, reaches, kept);
  joined[0] = 0;
  cv::dilate(kept, kept, grow);
  for (int y = 0; y < labels.rows; ++y) {
    const int* label = reach_labels.ptr<int>(y);
    uint8_t* keep = kept.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) keep[x] |= joined[label[x]] != 0 ? 255 : 0;
  }
  in_front(bounds) = kept & head_skin & ~face_pieces;
  // A hand's own creases and shading can shred it into pieces the opening takes, so that
  // little of it is kept. The skin beyond the face's pieces, taken whole, that goes on
  // outside the shapes (an arm) and of which less than kWholeShare was kept, is kept whole
  // (kInFrontWhole), unless it holds more of a face's centre than the face's piece does (a
  // face's own features shred it too, and its piece is then a part of it).
  cv::Mat rest_labels;
  const std::vector<RegionStats> rest_stats = LabelRegions(head_skin & ~face_zone, &rest_labels, 4);
  const int rests = static_cast<int>(rest_stats.size());
  std::vector<uint8_t> arm = LabelsMeeting(rest_labels, rests, outside);
  arm[0] = 0;
  const std::vector<std::vector<int>> rest_centre = in_centres(rest_labels, rests);
  for (size_t c = 0; c < rest_centre.size(); ++c) {
    for (int r = 1; r < rests; ++r) arm[r] &= rest_centre[c][r] <= face_centre[c] ? 1 : 0;
  }
  std::vector<int> covered(rests, 0);
  cv::Mat front = in_front(bounds);
  for (int y = 0; y < labels.rows; ++y) {
    const int* rest = rest_labels.ptr<int>(y);
    const uint8_t* in = front.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) covered[rest[x]] += in[x] != 0;
  }
  for (int r = 1; r < rests; ++r) arm[r] &= covered[r] < kWholeShare * rest_stats[r].area ? 1 : 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* rest = rest_labels.ptr<int>(y);
    uint8_t* in = front.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (in[x] == 0 && arm[rest[x]] != 0) in[x] = kInFrontWhole;
    }
  }
  return in_front;
}

}  // namespace

cv::Mat SkinSegmentation::Mask(const std::vector<int>& which, cv::Rect box) const {
  box &= cv::Rect(0, 0, frame.width, frame.height);
  if (scale == 1) {
    cv::Mat mask = cv::Mat::zeros(box.size(), CV_8UC1);
    for (int label : which) mask |= labels(box) == label;
    return mask;
  }
  // The working pixels under the box and one more each way, their mask interpolated up to
  // the frame's pixels and cut at half: edges fall between working pixels, not on them.
  const int x0 = box.x / scale - 1, y0 = box.y / scale - 1;
  const int x1 = (box.x + box.width + scale - 1) / scale + 1, y1 = (box.y + box.height + scale - 1) / scale + 1;
  const cv::Rect under = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, labels.cols, labels.rows);
  cv::Mat small = cv::Mat::zeros(under.size(), CV_8UC1);
  for (int label : which) small |= labels(under) == label;
  cv::Mat large;
  cv::resize(small, large, cv::Size(under.width * scale, under.height * scale), 0.0, 0.0, cv::INTER_LINEAR);
  return large(cv::Rect(box.x - under.x * scale, box.y - under.y * scale, box.width, box.height)) >= 128;
}

std::optional<SkinSegmenter::FaceChroma> SkinSegmenter::FaceChromaOf(const cv::Mat& ycrcb,
                                                                     const std::vector<cv::Rect>& faces) const {
  // The skin-coloured pixels of each face's cheeks, nose and mouth (an ellipse within its
  // box, below the eyes' line and short of the hair and the jaw's edge).
  double n = 0.0, cr = 0.0, cb = 0.0, crcr = 0.0, crcb = 0.0, cbcb = 0.0;
  for (const cv::Rect& face : faces) {
    cv::Mat inner = cv::Mat::zeros(face.size(), CV_8UC1);
    cv::ellipse(inner, cv::Point(face.width / 2, face.height * 11 / 20), cv::Size(face.width * 3 / 10, face.height * 7 / 20), 0,
                0, 360, cv::Scalar(255), cv::FILLED);
    const cv::Rect within = face & cv::Rect(0, 0, ycrcb.cols, ycrcb.rows);
    for (int y = within.y; y < within.y + within.height; ++y) {
      const cv::Vec3b* in = ycrcb.ptr<cv::Vec3b>(y);
      const uint8_t* mark = inner.ptr<uint8_t>(y - face.y);
      for (int x = within.x; x < within.x + within.width; ++x) {
        if (mark[x - face.x] == 0 || in[x][0] < options_.y_min || lookup_.data[in[x][1] * 256 + in[x][2]] != kSkin) continue;
        const double r = (in[x][1] - 128.0) / in[x][0], b = (in[x][2] - 128.0) / in[x][0];
        n += 1.0;
        cr += r;
        cb += b;
        crcr += r * r;
        crcb += r * b;
        cbcb += b * b;
      }
    }
  }
  if (n < kFaceChromaLeast) return std::nullopt;
  FaceChroma chroma;
  const double mean_cr = cr / n, mean_cb = cb / n;
  chroma.reach = options_.face_chroma * options_.face_chroma;
  const double srr = crcr / n - mean_cr * mean_cr, srb = crcb / n - mean_cr * mean_cb, sbb = cbcb / n - mean_cb * mean_cb;
  for (int y = std::max(options_.y_min, 1); y < 256; ++y) {
    // A level of chroma is 1 / y of this measure: the floor widens dim pixels' reach more.
    const double floor = (kFaceChromaFloor / y) * (kFaceChromaFloor / y);
    const double rr = srr + floor, bb = sbb + floor, det = (rr * bb - srb * srb) * y * y;
    chroma.levels[y] = {mean_cr * y, mean_cb * y, bb / det, -srb / det, rr / det};
  }
  return chroma;
}

SkinSegmentation SkinSegmenter::Segment(const cv::Mat& bgr, cv::Rect hand) {
  NPHAND_THROW_CHECK(!bgr.empty() && bgr.type() == CV_8UC3, "skin: a frame must be a non-empty 8-bit BGR image");
  SkinSegmentation out;
  out.frame = bgr.size();
  const cv::Mat work = Working(bgr, options_.work_width, &out.scale);
  const int scale = out.scale;
  cv::Mat ycrcb;
  cv::cvtColor(work, ycrcb, cv::COLOR_BGR2YCrCb);
  // A size in frame pixels at the working resolution: odd, so that the kernel is centred.
  auto working = [&](int px) { return ((px + scale - 1) / scale) | 1; };
  // The skin (and its rim) by the colour model, within `face` where one is given, cleaned.
  auto classify = [&](const FaceChroma* face) {
    out.skin.create(work.size(), CV_8UC1);
    cv::Mat rim(work.size(), CV_8UC1);
    for (int y = 0; y < ycrcb.rows; ++y) {
      const cv::Vec3b* in = ycrcb.ptr<cv::Vec3b>(y);
      uint8_t* skin = out.skin.ptr<uint8_t>(y);
      uint8_t* rim_row = rim.ptr<uint8_t>(y);
      for (int x = 0; x < ycrcb.cols; ++x) {
        uint8_t kind = in[x][0] >= options_.y_min ? lookup_.data[in[x][1] * 256 + in[x][2]] : 0;
        if (kind != 0 && face != nullptr && !face->Holds(in[x][0], in[x][1], in[x][2])) kind = 0;
        skin[x] = kind == kSkin ? 255 : 0;
        rim_row[x] = kind == kRim ? 255 : 0;
      }
    }
    if (options_.rim_area > 0.0) AddRim(static_cast<int>(options_.rim_area * work.total()), &rim, &out.skin);
    if (options_.open_px > 1) {
      const int k = working(options_.open_px);
      cv::morphologyEx(out.skin, out.skin, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    }
    if (options_.close_px > 1) {
      const int k = working(options_.close_px);
      cv::morphologyEx(out.skin, out.skin, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    }
  };
  // The fixed model's ungated skin is classified only where the cascade looks (it looks
  // around that skin's regions) or where no face's chroma gates the skin (below); elsewhere
  // the gated pass is the only one.
  bool classified = false;

  // Faces: looked for every face_interval frames, at once when a region that could hold
  // one came into view on the last frame (someone came in; a hand split by its object, or
  // moving, is not new), and every face_relook frames while the hand is over a face's box;
  // the cascade costs more than the rest of the frame. Between looks each face found is
  // followed, as the camera moves. A face's skin (the head's ellipse and the neck below it)
  // is set aside before the regions are found, so that a hand in front of a face keeps the
  // rest of itself.
  const bool periodic = frames_ % options_.face_interval == 0;
  const bool hand_over_face = hand.area() > 0 && std::any_of(faces_.begin(), faces_.end(), [&](const cv::Rect& face) {
    return 2 * (face & hand).area() >= hand.area();
  });
  const bool look = periodic || newcomer_ || (hand_over_face && frames_ - last_look_ >= options_.face_relook);
  // Every kFullLooks-th periodic look seeks faces of every size around the faces followed too.
  const bool full = periodic && (frames_ / options_.face_interval) % kFullLooks == 0;
  if (look) last_look_ = frames_;
  ++frames_;
  // The cascade sees the frame halved until it is at most 320 pixels wide.
  int halvings = 0;
  for (int width = work.cols; width > 320; width = (width + 1) / 2) ++halvings;
  const int look_scale = 1 << halvings;  // working pixels per looked-at pixel
  const int to_frame = look_scale * scale;
  constexpr int kMinFace = 24;           // pixels, in the looked-at frame
  const int face_side = kMinFace * look_scale / 2;  // a region's least side that could hold one, working pixels
  const cv::Rect whole(0, 0, work.cols, work.rows);
  // A face's box (frame pixels) in working pixels; the working pixels within a box, grey.
  auto working_box = [&](const cv::Rect& r) { return cv::Rect(r.x / scale, r.y / scale, r.width / scale, r.height / scale); };
  auto grey_of = [&](const cv::Rect& r) {
    cv::Mat grey;
    cv::cvtColor(work(r), grey, cv::COLOR_BGR2GRAY);
    return grey;
  };
  // Follows face i: its grey look (kFollowSide pixels wide) matched around where it was last
  // seen, a face's side each way; where it matches it is the face's new place. False where
  // it does not match (covered, or gone). The place is kept to a fraction of a working pixel
  // (the match's peak by a parabola through it and its neighbours). The look is taken
  // afresh there only when it matches less well than kRefreshScore (a turned, rolled or
  // nearer face): taken at every match, each match's error would add up, and a face
  // drifting by less than half a pixel of its look each frame (several of the frame's)
  // would be left behind or run ahead of.
  auto follow = [&](size_t i) {
    cv::Rect& face = faces_[i];
    FaceLook& seen = face_looks_[i];
    const cv::Rect at = working_box(face);
    const cv::Point corner(static_cast<int>(std::floor(seen.corner.x)), static_cast<int>(std::floor(seen.corner.y)));
    const cv::Rect roi = cv::Rect(corner.x - at.width, corner.y - at.height, at.width * 3, at.height * 3) & whole;
    const double shrink = static_cast<double>(kFollowSide) / at.width;
    cv::Mat small;
    cv::resize(grey_of(roi), small, cv::Size(), shrink, shrink, cv::INTER_AREA);
    if (small.cols < seen.grey.cols || small.rows < seen.grey.rows) return false;
    cv::Mat score;
    cv::matchTemplate(small, seen.grey, score, cv::TM_CCOEFF_NORMED);
    double best = 0.0;
    cv::Point where;
    cv::minMaxLoc(score, nullptr, &best, nullptr, &where);
    if (best < kFollowScore) return false;
    // The vertex of the parabola through a peak and its neighbours, off the peak (within half
    // a pixel).
    auto vertex = [](float before, float top, float after) {
      const double curve = before - 2.0 * top + after;
      return curve < 0.0 ? std::clamp(0.5 * (before - after) / curve, -0.5, 0.5) : 0.0;
    };
    cv::Point2d peak(where);
    if (where.x > 0 && where.x + 1 < score.cols) {
      const float* row = score.ptr<float>(where.y);
      peak.x += vertex(row[where.x - 1], row[where.x], row[where.x + 1]);
    }
    if (where.y > 0 && where.y + 1 < score.rows) {
      peak.y += vertex(score.at<float>(where.y - 1, where.x), score.at<float>(where.y, where.x),
                       score.at<float>(where.y + 1, where.x));
    }
    seen.corner = cv::Point2d(roi.x + peak.x / shrink, roi.y + peak.y / shrink);
    face.x = static_cast<int>(std::lround(seen.corner.x * scale));
    face.y = static_cast<int>(std::lround(seen.corner.y * scale));
    if (best < kRefreshScore) {
      const cv::Size side = seen.grey.size();
      const cv::Point2f centre(static_cast<float>(peak.x + (side.width - 1) / 2.0),
                               static_cast<float>(peak.y + (side.height - 1) / 2.0));
      cv::getRectSubPix(small, side, centre, seen.grey);
    }
    return true;
  };
  if (detector_ != nullptr && look) {
    classify(nullptr);
    classified = true;
    // The faces followed so far that still match where they were: the cascade misses a face
    // a hand covers in part, and such a face is kept.
    std::vector<cv::Rect> followed;
    std::vector<FaceLook> followed_looks;
    for (size_t i = 0; i < faces_.size(); ++i) {
      if (!follow(i)) continue;
      followed.push_back(faces_[i]);
      followed_looks.push_back(face_looks_[i]);
    }
    // A face is skin: the cascade looks only around skin regions that could hold one (their
    // box grown by a quarter of a side each way, for the hair and a face cut by a hand).
    out.faces_looked = true;
    cv::Mat labels;
    const std::vector<RegionStats> stats = LabelRegions(out.skin, &labels);
    std::vector<cv::Rect> looked;
    faces_.clear();
    for (size_t label = 1; label < stats.size(); ++label) {
      const cv::Rect& box = stats[label].box;
      if (box.width < face_side || box.height < face_side) continue;
      const cv::Rect roi =
          cv::Rect(box.x - box.width / 4, box.y - box.height / 4, box.width * 3 / 2, box.height * 3 / 2) & whole;
      if (std::any_of(looked.begin(), looked.end(), [&](const cv::Rect& r) { return (r & roi) == roi; })) continue;
      looked.push_back(roi);
      cv::Mat grey = grey_of(roi);
      for (int h = 0; h < halvings; ++h) cv::pyrDown(grey, grey);
      if (grey.cols < kMinFace || grey.rows < kMinFace) continue;
      cv::equalizeHist(grey, grey);
      // Around a face followed here, a look between full ones seeks faces of its size only:
      // it finds that face again (its box as it grows or shrinks); the small scales, which
      // cost the most, wait for the next full look. Where it finds none (the face covered, or
      // grown or shrunk past the band since the last look), every size is sought after all.
      cv::Size least(kMinFace, kMinFace), most;
      if (!full) {
        int narrowest = 0, widest = 0;
        for (const cv::Rect& face : followed) {
          const cv::Rect at = working_box(face);
          if (2 * (at & roi).area() < at.area()) continue;
          const int side = at.width / look_scale;
          narrowest = narrowest == 0 ? side : std::min(narrowest, side);
          widest = std::max(widest, side);
        }
        if (widest > 0) {
          const int low = std::max(kMinFace, static_cast<int>(kBandBelow * narrowest));
          const int high = std::max(low, static_cast<int>(std::ceil(kBandAbove * widest)));
          least = cv::Size(low, low);
          most = cv::Size(high, high);
        }
      }
      std::vector<cv::Rect> found;
      detector_->cascade.detectMultiScale(grey, found, 1.1, 4, 0, least, most);
      if (found.empty() && most.area() > 0) {
        detector_->cascade.detectMultiScale(grey, found, 1.1, 4, 0, cv::Size(kMinFace, kMinFace));
      }
      for (const cv::Rect& f : found) {
        const cv::Rect face(roi.x * scale + f.x * to_frame, roi.y * scale + f.y * to_frame, f.width * to_frame,
                            f.height * to_frame);
        const int shared = (face & hand).area();
        if (!periodic && 2 * shared > face.area() && 2 * shared > hand.area()) continue;
        if (std::none_of(faces_.begin(), faces_.end(), [&](const cv::Rect& g) { return (g & face).area() > 0; })) {
          faces_.push_back(face);
        }
      }
    }
    face_looks_.clear();
    for (const cv::Rect& face : faces_) {
      const cv::Rect at = working_box(face) & whole;
      FaceLook taken;
      cv::resize(grey_of(at), taken.grey, cv::Size(kFollowSide, kFollowSide * at.height / std::max(1, at.width)), 0.0, 0.0,
                 cv::INTER_AREA);
      taken.corner = at.tl();
      face_looks_.push_back(std::move(taken));
    }
    for (size_t i = 0; i < followed.size(); ++i) {
      const cv::Rect& face = followed[i];
      if (std::any_of(faces_.begin(), faces_.end(), [&](const cv::Rect& g) { return (g & face).area() > 0; })) continue;
      faces_.push_back(face);
      face_looks_.push_back(followed_looks[i]);
    }
  } else {
    // Each face is followed; one not seen stays where it was until the next look.
    for (size_t i = 0; i < faces_.size(); ++i) follow(i);
  }
  out.faces = faces_;
  // The faces' own skin tells the person's: the skin is found again within the colours near
  // it, which a warm wall, blonde hair or a cream sweater that the fixed model takes lie
  // outside of.
  if (options_.face_chroma > 0.0 && !faces_.empty()) {
    const std::optional<FaceChroma> face = FaceChromaOf(ycrcb, [&] {
      std::vector<cv::Rect> boxes;
      for (const cv::Rect& box : faces_) boxes.push_back(working_box(box));
      return boxes;
    }());
    if (face) {
      classify(&*face);
      classified = true;
    }
  }
  if (!classified) classify(nullptr);
  // Each face's head (an ellipse about its box) and, with `necks`, neck (a rectangle
  // below), grown by `grow` faces' widths, drawn into `mask` (working pixels); returns their
  // bounds.
  auto draw_faces = [&](double grow, bool necks, cv::Mat* mask) {
    cv::Rect bounds;
    for (const cv::Rect& frame_face : faces_) {
      const cv::Rect f = working_box(frame_face);
      const int g = static_cast<int>(grow * f.width);
      const cv::Point centre(f.x + f.width / 2, f.y + f.height / 2);
      const cv::Size head(f.width * 7 / 10 + g, f.height * 9 / 10 + g);
      const cv::Rect neck(f.x + f.width / 5 - g, centre.y, f.width * 3 / 5 + 2 * g, f.height * 3 / 2 + g);
      cv::ellipse(*mask, centre, head, 0, 0, 360, cv::Scalar(255), cv::FILLED);
      bounds |= cv::Rect(centre - cv::Point(head.width, head.height), centre + cv::Point(head.width, head.height));
      if (!necks) continue;
      cv::rectangle(*mask, neck, cv::Scalar(255), cv::FILLED);
      bounds |= neck;
    }
    return bounds & whole;
  };
  // Skin a face's outline parts from it (a hand in front of it), working pixels: pieces of
  // at least least_hand, kInFrontShare of the smallest face's box (a hand near a face is
  // about as large as it), or going on outside the heads and necks.
  int smallest_face = work.cols * work.rows;
  for (const cv::Rect& face : faces_) smallest_face = std::min(smallest_face, working_box(face).area());
  const double least_hand = kInFrontShare * smallest_face;
  cv::Mat in_front;
  if (!faces_.empty()) {
    cv::Mat face_mask = cv::Mat::zeros(work.size(), CV_8UC1);
    draw_faces(0.0, true, &face_mask);
    if (options_.part_faces) {
      // Only within the heads: a chin's edge parts every neck from its face.
      cv::Mat heads = cv::Mat::zeros(work.size(), CV_8UC1);
      const cv::Rect bounds = draw_faces(0.0, false, &heads);
      std::vector<cv::Rect> centres;
      for (const cv::Rect& face : faces_) {
        const cv::Rect f = working_box(face);
        centres.emplace_back(f.x + f.width / 4, f.y + f.height / 4, f.width / 2, f.height / 2);
      }
      in_front = InFrontOfFaces(work, out.skin, heads, face_mask, bounds, centres, least_hand);
      face_mask.setTo(0, in_front);
    }
    out.face_pixels = cv::countNonZero(out.skin & face_mask) * scale * scale;
    out.skin.setTo(0, face_mask);
  }

  const std::vector<RegionStats> stats = LabelRegions(out.skin, &out.labels);
  // What the set-aside shapes leave of a head or neck (the edge of a wider neck, a cheek):
  // regions lying almost wholly within a fifth of a face's width of them, unless they hold
  // skin in front of a face, lie beside such a region or are of a hand's size (least_hand):
  // a leftover is a sliver.
  std::vector<int> near_face;  // by label: its pixels in the zone (empty without faces)
  std::vector<uint8_t> before_face;  // by label: it holds skin in front of a face
  std::vector<uint8_t> parted_front;  // by label: it holds skin an outline parts from a face
  if (!faces_.empty()) {
    near_face.assign(stats.size(), 0);
    before_face.assign(stats.size(), 0);
    parted_front.assign(stats.size(), 0);
    cv::Mat zone = cv::Mat::zeros(work.size(), CV_8UC1);
    const cv::Rect bounds = draw_faces(0.2, true, &zone);
    for (int y = bounds.y; y < bounds.y + bounds.height; ++y) {
      const uint8_t* in_zone = zone.ptr<uint8_t>(y);
      const uint8_t* front = in_front.empty() ? nullptr : in_front.ptr<uint8_t>(y);
      const int* label = out.labels.ptr<int>(y);
      for (int x = bounds.x; x < bounds.x + bounds.width; ++x) {
        near_face[label[x]] += in_zone[x] != 0;
        if (front == nullptr || front[x] == 0) continue;
        before_face[label[x]] = 1;
        if (front[x] != kInFrontWhole) parted_front[label[x]] = 1;
      }
    }
  }
  const int min_area = std::max(1, static_cast<int>(options_.min_area * work.total()));
  // Nor are pieces beside skin in front of a face (fingers an object or an outline split
  // from the hand over the face): within the reach of such a region, as the estimator
  // gathers a hand's pieces.
  std::vector<cv::Rect> reaches;
  for (size_t label = 1; label < before_face.size(); ++label) {
    if (before_face[label] != 0 && stats[label].area >= min_area) reaches.push_back(HandReach(stats[label].box));
  }
  auto beside_front = [&](const cv::Rect& box) {
    return std::any_of(reaches.begin(), reaches.end(), [&](const cv::Rect& r) { return (r & box).area() > 0; });
  };
  // A body dressed in skin colours below a face (a sweater, a bare chest; the neck's
  // rectangle, a sweater's ribs and the frame's side may split it): the pieces that meet the
  // frame's bottom edge within the face's column, grown by the face's width each side, each
  // over at least kBodyPiece of the face's width and at most kBodyHeight times as tall as
  // that, when together they span at least kBodyWidths of it. An arm raised from the bottom
  // meets it over its wrist's width and is taller than that.
  std::vector<uint8_t> body(stats.size(), 0);
  if (!faces_.empty() && options_.set_aside_bodies) {
    const int* bottom = out.labels.ptr<int>(work.rows - 1);
    for (const cv::Rect& face : faces_) {
      const cv::Rect f = working_box(face);
      const int from = std::max(0, f.x - f.width), to = std::min(work.cols, f.x + 2 * f.width);
      std::vector<int> met(stats.size(), 0);
      for (int x = from; x < to; ++x) ++met[bottom[x]];
      auto piece = [&](int label) {
        return label != 0 && met[label] >= kBodyPiece * f.width && stats[label].box.height <= kBodyHeight * met[label] &&
               (parted_front.empty() || parted_front[label] == 0);
      };
      int left = to, right = from;
      for (int x = from; x < to; ++x) {
        if (!piece(bottom[x])) continue;
        left = std::min(left, x);
        right = std::max(right, x + 1);
      }
      if (right - left < kBodyWidths * f.width) continue;
      for (size_t label = 1; label < stats.size(); ++label) body[label] |= piece(static_cast<int>(label));
    }
  }
  const cv::Rect frame(0, 0, bgr.cols, bgr.rows);
  for (size_t label = 1; label < stats.size(); ++label) {
    const RegionStats& found = stats[label];
    if (found.area < min_area) continue;
    if (!near_face.empty() && before_face[label] == 0 && near_face[label] >= 0.8 * found.area &&
        found.area < least_hand && !beside_front(found.box)) {
      out.face_pixels += found.area * scale * scale;
      continue;
    }
    if (body[label] != 0) {
      out.body_pixels += found.area * scale * scale;
      continue;
    }
    SkinRegion region;
    region.label = static_cast<int>(label);
    region.area = found.area * scale * scale;
    region.box = cv::Rect(found.box.x * scale, found.box.y * scale, found.box.width * scale, found.box.height * scale) & frame;
    // A working pixel's centre in the frame's pixel coordinates.
    region.centroid = cv::Point2d((found.centroid.x + 0.5) * scale - 0.5, (found.centroid.y + 0.5) * scale - 0.5);
    out.regions.push_back(region);
  }
  // A region that could hold a face and meets none of the last frame's such regions came
  // into view (unless the cascade has just looked at it).
  std::vector<cv::Rect> face_sized;
  newcomer_ = false;
  for (const SkinRegion& r : out.regions) {
    if (r.box.width < face_side * scale || r.box.height < face_side * scale) continue;
    face_sized.push_back(r.box);
    const bool met = std::any_of(face_sized_.begin(), face_sized_.end(),
                                 [&](const cv::Rect& before) { return (before & r.box).area() > 0; });
    newcomer_ = newcomer_ || (!out.faces_looked && !met);
  }
  face_sized_ = std::move(face_sized);
  std::sort(out.regions.begin(), out.regions.end(),
            [](const SkinRegion& a, const SkinRegion& b) { return a.area != b.area ? a.area > b.area : a.label < b.label; });
  // Only a frame without a region asks why: has it colour at all?
  if (out.regions.empty()) {
    out.colourless = true;
    for (int channel : {1, 2}) {
      cv::Mat chroma;
      cv::extractChannel(ycrcb, chroma, channel);
      double low = 0.0, high = 0.0;
      cv::minMaxLoc(chroma, &low, &high);
      out.colourless = out.colourless && low >= 128 - kColourlessChroma && high <= 128 + kColourlessChroma;
    }
  }
  return out;
}

void SkinSegmenter::Learn(const cv::Mat& bgr, const cv::Mat& hand) {
  if (!options_.adapt) return;
  NPHAND_THROW_CHECK(!bgr.empty() && bgr.type() == CV_8UC3 && hand.type() == CV_8UC1 && hand.size() == bgr.size(),
                     "skin: learning needs a BGR frame and a hand mask of its size");
  // At the working resolution, as Segment sees the frame.
  int scale = 1;
  const cv::Mat work = Working(bgr, options_.work_width, &scale);
  cv::Mat hand_work = hand != 0;
  if (scale > 1) cv::resize(hand_work, hand_work, work.size(), 0.0, 0.0, cv::INTER_AREA);
  cv::Mat ycrcb;
  cv::cvtColor(work, ycrcb, cv::COLOR_BGR2YCrCb);
  // The hand's inside (its edges mix with the background) against everything not near it:
  // 2 and 7 frame pixels, in working pixels.
  const int erode_px = 2 * std::max(1, 2 / scale) + 1, dilate_px = 2 * std::max(1, 7 / scale) + 1;
  cv::Mat inner, near;
  cv::erode(hand_work >= 128, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(erode_px, erode_px)));
  cv::dilate(hand_work != 0, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(dilate_px, dilate_px)));
  if (cv::countNonZero(inner) < 50) return;
  const int channels[] = {1, 2};
  const int sizes[] = {options_.bins, options_.bins};
  const float range[] = {0.0f, 256.0f};
  const float* ranges[] = {range, range};
  cv::Mat hand_now, rest_now;
  cv::calcHist(&ycrcb, 1, channels, inner, hand_now, 2, sizes, ranges);
  cv::calcHist(&ycrcb, 1, channels, near == 0, rest_now, 2, sizes, ranges);
  const double hand_sum = cv::sum(hand_now)[0], rest_sum = cv::sum(rest_now)[0];
  if (hand_sum <= 0.0 || rest_sum <= 0.0) return;
  hand_now /= hand_sum;
  rest_now /= rest_sum;
  const double rate = learned_ == 0 ? 1.0 : options_.learn_rate;
  hand_hist_ = (1.0 - rate) * hand_hist_ + rate * hand_now;
  rest_hist_ = (1.0 - rate) * rest_hist_ + rate * rest_now;
  ++learned_;
  RebuildLookup();
}

}  // namespace nphand

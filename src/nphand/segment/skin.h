// Skin segmentation of camera frames: which pixels are skin, which connected regions they
// form, which of those may be the hand. A fixed colour model in YCrCb chroma to start, then
// adapted to the tracked hand's own colours (a hand-against-rest histogram learned from
// confident frames, updated slowly); morphological clean-up; connected components; faces
// found by OpenCV's Haar cascade (Debian's opencv-data) and their skin set aside.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nphand {

// Debian's opencv-data frontal face cascade.
inline constexpr const char* kDefaultFaceCascade = "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml";

struct SkinOptions {
  // The fixed model: a box in OpenCV's 8-bit YCrCb (Chai and Ngan's Cr 133..173, Cb 77..127)
  // above a floor of luma, below which chroma is mostly noise.
  int cr_min = 133, cr_max = 173, cb_min = 77, cb_max = 127, y_min = 30;
  // Skin's rim: chroma in this wider box but outside the one above (flushed fingertips and
  // knuckles under warm light reach Cr 185) is skin where it lies in a connected piece that
  // meets skin and covers at most rim_area of the frame (a warm wall beside the hand is no
  // fingertip). rim_area 0: no rim. Below Cr 133 (a palm in cool light) the rim took the
  // shaded side of real-dev's forearm: docs/estimator.md.
  int rim_cr_min = 133, rim_cr_max = 190, rim_cb_min = 70, rim_cb_max = 135;
  double rim_area = 0.015;
  // Adaptation: after Learn, a pixel is skin if it is in the box and P(hand | Cr, Cb) >=
  // keep, or anywhere if P >= add; P compares the hand's chroma histogram with the rest of
  // the frame's. Each Learn moves the histograms by learn_rate towards the new frame's.
  bool adapt = true;
  double learn_rate = 0.1;
  double keep = 0.25;
  double add = 0.8;
  int bins = 32;                // per chroma axis
  // Frames wider than this are halved (2 x 2 means) until they are not, and segmented at
  // that working resolution (0: at the frame's own); region masks come back at the frame's
  // resolution, their edges interpolated. A 640 x 480 frame is segmented at 320 x 240.
  int work_width = 320;
  // Morphology, in frame pixels (at the working resolution: divided by its scale, rounded
  // up to an odd size).
  int open_px = 3;              // opening removes specks (0: none)
  int close_px = 5;             // closing fills cracks; wider holes stay (the object's)
  double min_area = 0.0003;     // smallest region, as a fraction of the frame (fingertips past an object count)
  // Faces: the cascade's file ("" finds none), run every face_interval frames and on the
  // frame after a skin region large enough to hold a face came into view (its box meets no
  // such region's box of the frame before), around those regions, on the frame halved
  // until it is at most 320 pixels wide; between its runs each face found is followed (its
  // grey look, as last taken, matched around where it was last seen); each face's head and neck are
  // set aside from the skin. Around a face followed, a look seeks faces of about its size
  // only, except every fourth periodic look, which seeks them all.
  std::string face_cascade = kDefaultFaceCascade;
  int face_interval = 30;
  // While the hand found last lies half or more within a face's box, the face is looked for
  // again every face_relook frames: its box was found before the hand came over it, and
  // followed since by a look the hand now shares.
  int face_relook = 5;
  // A hand held in front of a face: of the skin within a face's head, the pieces that the
  // frame's edges (Canny on grey) part from the skin at the face's centre, if not much
  // smaller than a hand, are something in front of the face and stay skin; the rest, and
  // the neck, are the face's.
  bool part_faces = true;
  // A body dressed in skin colours below a face (a sweater, a bare chest): the regions that
  // meet the frame's bottom edge below a face, each over at least kBodyPiece face widths
  // and at most kBodyHeight times as tall as that, and together span at least kBodyWidths
  // face widths, are set aside as no hand.
  bool set_aside_bodies = true;
  // The person's own skin: while a face is in view, skin is only the colour within
  // face_chroma standard deviations (Mahalanobis) of its cheeks' pixels, over the chroma
  // divided by the brightness ((Cr - 128) / Y, (Cb - 128) / Y: a shadow dims skin, and its
  // chroma with it, without changing this), their spread widened by kFaceChromaFloor levels
  // of chroma each way (0: the fixed and learned models alone).
  double face_chroma = 3.0;
  bool Check(std::string* why) const;
};

// A connected skin region, in the frame's pixels.
struct SkinRegion {
  int label = 0;              // in SkinSegmentation::labels
  cv::Rect box;
  int area = 0;               // pixels
  cv::Point2d centroid;
};

// How far (8-bit Cr and Cb levels) from grey a colourless frame's pixels may lie: a JPEG
// of a grey image keeps its chroma within a level or two of 128.
inline constexpr int kColourlessChroma = 3;

struct SkinSegmentation {
  cv::Size frame;                   // the frame's size
  int scale = 1;                    // frame pixels per working pixel (a power of 2)
  cv::Mat skin;                     // CV_8UC1, working resolution, 255 = skin (cleaned, faces set aside)
  cv::Mat labels;                   // CV_32SC1, working resolution, connected regions of `skin` (0: none)
  std::vector<SkinRegion> regions;  // at least min_area, largest first
  std::vector<cv::Rect> faces;      // the faces in view (the last look's, followed since), frame pixels
  int face_pixels = 0;              // frame pixels of skin set aside as faces (heads, necks and what they leave of them)
  int body_pixels = 0;              // frame pixels of skin set aside as bodies below faces (SkinOptions::set_aside_bodies)
  bool faces_looked = false;        // the face cascade ran on this frame
  // A frame without regions that has no colour (greyscale, or an infrared camera's): every
  // pixel's chroma lies within kColourlessChroma of grey, so skin colour cannot be told from
  // anything else. Looked at only when no region was found (false otherwise).
  bool colourless = false;
  // The pixels of the regions labelled `which` within `box` (frame pixels), at the frame's
  // resolution: CV_8UC1 of the box's size, 255 = skin.
  cv::Mat Mask(const std::vector<int>& which, cv::Rect box) const;
  // The pixels of one region within its box.
  cv::Mat RegionMask(const SkinRegion& region) const;
};

class SkinSegmenter {
 public:
  // Throws nphand::Error for invalid options or a face cascade that cannot be loaded.
  explicit SkinSegmenter(const SkinOptions& options = {});

  // Throws nphand::Error unless `bgr` is a non-empty 8-bit 3-channel image. `hand`: where
  // the hand was just found (frame pixels; empty: nowhere). The cascade takes a fist for a
  // face at times: on a look that a newcomer fired (the hand's own region changing shape),
  // or the hand over a face (face_relook), a face found where the hand was (most of each
  // box within the other) is ignored. The looks of every face_interval frames believe the
  // cascade, so that a track on a face lets go of it.
  SkinSegmentation Segment(const cv::Mat& bgr, cv::Rect hand = {});

  // Learns the hand's colours from a confidently estimated frame: `hand` (CV_8UC1 of the
  // frame's size, non-zero = the hand's pixels) against the rest of the frame.
  void Learn(const cv::Mat& bgr, const cv::Mat& hand);
  bool adapted() const { return learned_ > 0; }
  // Forgets what was learned and the faces (a new video).
  void Reset();

 private:
  void RebuildLookup();
  // The colours of the faces' skin (SkinOptions::face_chroma), per brightness Y over the
  // levels' chroma (Cr - 128, Cb - 128): the mean of ((Cr - 128) / Y, (Cb - 128) / Y) times Y,
  // and the inverse of its spread (widened by kFaceChromaFloor / Y) over Y², so that a pixel
  // is judged without a division.
  struct FaceChroma {
    struct Level {
      double cr = 0.0, cb = 0.0;            // the mean, times Y
      double rr = 0.0, rb = 0.0, bb = 0.0;  // the inverse spread, over Y²
    };
    std::array<Level, 256> levels{};
    double reach = 0.0;  // squared Mahalanobis distance allowed
    bool Holds(int y, int cr_level, int cb_level) const {
      if (y == 0) return false;
      const Level& l = levels[y];
      const double r = cr_level - 128.0 - l.cr, b = cb_level - 128.0 - l.cb;
      return l.rr * r * r + 2.0 * l.rb * r * b + l.bb * b * b <= reach;
    }
  };
  // From `ycrcb` (the working frame) and the faces' boxes in its pixels; nullopt when the
  // faces show too little skin to tell.
  std::optional<FaceChroma> FaceChromaOf(const cv::Mat& ycrcb, const std::vector<cv::Rect>& faces) const;

  SkinOptions options_;
  static constexpr uint8_t kSkin = 255, kRim = 128;
  cv::Mat lookup_;                 // CV_8UC1, 256 x 256 over (Cr, Cb): kSkin, kRim (SkinOptions::rim_area) or 0
  cv::Mat hand_hist_, rest_hist_;  // CV_32FC1, bins x bins, each summing to 1
  int learned_ = 0;
  int frames_ = 0;
  std::vector<cv::Rect> face_sized_;  // the last frame's regions that could hold a face
  bool newcomer_ = false;             // one of them met none of the frame before's
  int last_look_ = 0;                 // the frame the cascade last ran on
  std::vector<cv::Rect> faces_;
  struct FaceLook {
    cv::Mat grey;        // its grey pixels, kFollowSide wide, as taken at a look or where a match fell below kRefreshScore
    cv::Point2d corner;  // its box's top-left corner where it was last matched, working pixels (to a fraction of one)
  };
  std::vector<FaceLook> face_looks_;  // by face
  static constexpr int kFollowSide = 24;
  static constexpr double kFollowScore = 0.5;  // normalised correlation a followed face must reach
  static constexpr double kRefreshScore = 0.8;  // below it, a followed face's look is taken afresh
  // Between full looks (every kFullLooks-th periodic one), the cascade seeks faces of
  // kBandBelow to kBandAbove times the width of a face followed within its region.
  static constexpr int kFullLooks = 4;
  static constexpr double kBandBelow = 0.8, kBandAbove = 1.25;
  static constexpr double kInFrontShare = 0.15;  // least piece in front of a face, of its box
  static constexpr double kBodyWidths = 1.25;    // a body's least span along the frame's bottom edge, in faces
  static constexpr double kBodyPiece = 0.25;     // a body's piece's least width along that edge, in faces
  static constexpr double kFaceChromaLeast = 30;  // working pixels of a face's skin that tell its chroma
  static constexpr double kFaceChromaFloor = 6.0;  // levels of chroma added to its spread each way
  static constexpr double kBodyHeight = 3.0;     // a body's piece's greatest height, in its width along that edge (an arm is taller)
  struct FaceDetector;
  std::shared_ptr<FaceDetector> detector_;
};

}  // namespace nphand

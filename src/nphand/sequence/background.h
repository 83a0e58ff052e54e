// Procedural backgrounds and distractors for rendered frames that mimic a camera's: plain
// walls, textures, cluttered rooms, a face. Generated from a seed (no images are stored).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nphand {

enum class BackgroundKind : uint8_t {
  kPlain,    // one colour with a soft gradient of light
  kTexture,  // multi-scale value noise through a palette
  kClutter,  // a texture with many shapes in front of it: a room's objects and edges
};
std::string ToString(BackgroundKind kind);
// Accepts the names ToString gives; throws nphand::Error naming the choices otherwise.
BackgroundKind BackgroundKindFromString(const std::string& text);
std::vector<std::string> BackgroundKindNames();

// A BGR background of `size`. Its colours keep to hues from yellow-green to blue and greys,
// so that no background pixel has skin chroma: skin-coloured scenery is the skin model's
// named failure mode (PAPER.md), measured apart from these frames.
cv::Mat MakeBackground(BackgroundKind kind, cv::Size size, uint64_t seed);

// Draws a frontal face (skin-coloured head, darker eyes, brows and mouth) of height
// `height` pixels centred at `centre` onto `bgr`: a skin region that is not a hand.
void DrawFace(const cv::Vec3f& skin_bgr, cv::Point centre, int height, cv::Mat* bgr);

// Draws the shoulders and chest of the person whose face DrawFace puts at `centre` with
// `height`, in a sweater of colour `bgr_colour` (knitted ribs a little darker), down to the
// image's bottom. Drawn before the face, so that the neck lies over its collar.
void DrawSweater(const cv::Vec3f& bgr_colour, cv::Point centre, int height, cv::Mat* bgr);

}  // namespace nphand

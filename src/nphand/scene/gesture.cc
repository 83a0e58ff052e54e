#include "nphand/scene/gesture.h"

#include <algorithm>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr double kFormedFrom = 0.4;  // step 0's share of the way from the relaxed hand

// Degrees: thumb {cmc flex, cmc abd, cmc roll, mcp, ip}; fingers {mcp, abd, pip, dip}
// (abduction positive towards the thumb).
using Thumb = std::array<double, 5>;
using Finger = std::array<double, 4>;
constexpr Thumb kTucked = {30, -20, 50, 30, 20};   // over the curled fingers, as in a fist
constexpr Thumb kOut = {0, 35, 15, 0, 0};          // straight and away from the index, as in a thumbs-up
constexpr Thumb kAcross = {50, -15, 45, 55, 45};   // folded across the palm
constexpr Thumb kSpread = {0, 35, 40, 0, 0};       // open, as the grasps' pre-shape
constexpr Thumb kAlongside = {5, -25, 10, 0, 0};   // straight beside the index
constexpr Thumb kRing = {35, 20, 50, 20, 25};      // meeting the index's tip
constexpr Finger kCurled = {88, 0, 90, 60};
constexpr Finger Straight(double abduction) { return {0, abduction, 0, 0}; }

GestureDefinition Define(int number, const char* name, const Thumb& thumb, const Finger& index, const Finger& middle,
                         const Finger& ring, const Finger& little) {
  GestureDefinition g;
  g.id = kFirstGestureId + number;
  g.name = name;
  g.shape = AnglesFromDegrees(thumb, index, middle, ring, little);
  const std::array<Finger, 4> fingers = {index, middle, ring, little};
  // Straight at the PIP: the MCP only bends a straight finger.
  for (size_t f = 0; f < fingers.size(); ++f) g.extended[f] = fingers[f][2] < 45.0;
  return g;
}

}  // namespace

const std::vector<GestureDefinition>& Gestures() {
  static const std::vector<GestureDefinition> kGestures = [] {
    const Finger c = kCurled;
    const std::vector<GestureDefinition> all = {
        Define(0, "fist", kTucked, c, c, c, c),
        Define(1, "point", kTucked, Straight(0), c, c, c),
        Define(2, "peace", kTucked, Straight(10), Straight(-8), c, c),
        Define(3, "three", kOut, Straight(8), Straight(-5), c, c),
        Define(4, "three_fingers", kTucked, Straight(8), Straight(0), Straight(-8), c),
        Define(5, "four", kAcross, Straight(10), Straight(3), Straight(-5), Straight(-14)),
        Define(6, "open_palm", kSpread, Straight(15), Straight(3), Straight(-8), Straight(-18)),
        Define(7, "flat", kAlongside, Straight(0), Straight(0), Straight(0), Straight(0)),
        Define(8, "thumbs_up", kOut, c, c, c, c),
        Define(9, "l_shape", kOut, Straight(0), c, c, c),
        Define(10, "rock", kTucked, Straight(5), c, c, Straight(-10)),
        Define(11, "call", kOut, c, c, c, Straight(-15)),
        Define(12, "ok", kRing, {50, 0, 75, 50}, Straight(3), Straight(-5), Straight(-12)),
        Define(13, "pinkie", kTucked, c, c, c, Straight(-10)),
        Define(14, "middle_finger", kTucked, c, Straight(0), c, c),
        Define(15, "claw", kSpread, {20, 10, 80, 60}, {20, 0, 80, 60}, {20, -5, 80, 60}, {20, -10, 80, 60}),
    };
    NPHAND_CHECK(all.size() == kNumGestures);
    for (const GestureDefinition& g : all) {
      NPHAND_CHECK(ClampToLimits(g.shape) == g.shape, "gesture ", g.name, " leaves its limits");
    }
    return all;
  }();
  return kGestures;
}

const GestureDefinition& GestureByName(const std::string& name) {
  const std::string key = NameKey(name);
  std::string choices;
  for (const GestureDefinition& g : Gestures()) {
    if (g.name == key) return g;
    choices += (choices.empty() ? "" : ", ") + g.name;
  }
  NPHAND_THROW("unknown gesture '", name, "' (choices: ", choices, ")");
}

std::vector<int> GestureIds() {
  std::vector<int> ids;
  for (const GestureDefinition& g : Gestures()) ids.push_back(g.id);
  return ids;
}

std::vector<int> GestureIdsNamed(const std::vector<std::string>& names, const std::string& what) {
  const bool word = std::any_of(names.begin(), names.end(), [](const std::string& n) { return n == "all" || n == "none"; });
  NPHAND_THROW_CHECK(!word || names.size() == 1, what, ": 'all' and 'none' stand alone, not among names");
  if (word) return names[0] == "all" ? GestureIds() : std::vector<int>{};
  std::vector<int> ids;
  for (const std::string& name : names) ids.push_back(GestureByName(name).id);
  return ids;
}

bool IsGesture(int shape) { return shape >= kFirstGestureId && shape <= kNumHandShapes; }

std::array<JointAngles, kGraspSteps> GestureSteps(const GestureDefinition& gesture) {
  const JointAngles relaxed = NamedArticulation("relaxed");
  std::array<JointAngles, kGraspSteps> steps;
  for (int s = 0; s < kGraspSteps; ++s) {
    const double t = kFormedFrom + (1.0 - kFormedFrom) * s / (kGraspSteps - 1);
    for (int d = 0; d < kNumDofs; ++d) steps[s][d] = relaxed[d] + t * (gesture.shape[d] - relaxed[d]);
  }
  steps.back() = gesture.shape;  // exactly, not within rounding
  return steps;
}

std::string HandShapeKey(int shape) {
  NPHAND_CHECK(shape >= 1 && shape <= kNumHandShapes, "hand shape ", shape, " does not exist");
  return IsGesture(shape) ? Gestures()[shape - kFirstGestureId].name : GraspKey(GraspTaxonomy()[shape - 1]);
}

}  // namespace nphand

#include "nphand/scene/gesture.h"

#include <set>

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

TEST(GestureTest, GesturesFollowTheGraspsInOneNumbering) {
  const auto& gestures = Gestures();
  ASSERT_EQ(gestures.size(), static_cast<size_t>(kNumGestures));
  std::set<std::string> names;
  for (size_t i = 0; i < gestures.size(); ++i) {
    EXPECT_EQ(gestures[i].id, kFirstGestureId + static_cast<int>(i));
    EXPECT_TRUE(IsGesture(gestures[i].id));
    EXPECT_EQ(HandShapeKey(gestures[i].id), gestures[i].name);
    EXPECT_EQ(&GestureByName(gestures[i].name), &gestures[i]);
    names.insert(gestures[i].name);
  }
  EXPECT_EQ(names.size(), gestures.size());
  EXPECT_EQ(GestureByName("Thumbs Up").name, "thumbs_up");
  EXPECT_FALSE(IsGesture(kNumGrasps));
  EXPECT_EQ(HandShapeKey(1), "large_diameter");
  EXPECT_THROW(GestureByName("wave"), Error);
}

TEST(GestureTest, GesturesAreNamedOrAllOrNone) {
  EXPECT_EQ(GestureIdsNamed({"all"}, "x"), GestureIds());
  EXPECT_TRUE(GestureIdsNamed({"none"}, "x").empty());
  EXPECT_TRUE(GestureIdsNamed({}, "x").empty());
  EXPECT_EQ(GestureIdsNamed({"fist", "Thumbs Up"}, "x"),
            (std::vector<int>{GestureByName("fist").id, GestureByName("thumbs_up").id}));
  testing::ExpectError([] { GestureIdsNamed({"fist", "all"}, "--gestures"); }, "--gestures: 'all' and 'none' stand alone");
  testing::ExpectError([] { GestureIdsNamed({"wave"}, "--gestures"); }, "unknown gesture 'wave'");
}

// What the gesture says of each finger is what its posed hand shows, judged as real-dev's
// scorer judges finger states: extended when the MCP-to-tip distance exceeds 0.75 of the
// finger's bone lengths.
TEST(GestureTest, EachGesturesFingersAreStraightOrCurledAsItSays) {
  for (const GestureDefinition& g : Gestures()) {
    HandPose pose;
    pose.angles = GestureSteps(g)[kGraspSteps - 1];
    EXPECT_EQ(pose.angles, g.shape) << g.name;
    EXPECT_TRUE(pose.IsValid()) << g.name;
    EXPECT_EQ(FingerStates(RightHand().KeypointsOf(pose)), g.extended) << g.name;
  }
}

// A gesture's first step is the hand forming it, not the relaxed hand every gesture
// passes: no two gestures share a step.
TEST(GestureTest, NoTwoGesturesShareAStep) {
  for (size_t a = 0; a < Gestures().size(); ++a) {
    const auto steps_a = GestureSteps(Gestures()[a]);
    for (size_t b = a + 1; b < Gestures().size(); ++b) {
      const auto steps_b = GestureSteps(Gestures()[b]);
      for (int s = 0; s < kGraspSteps; ++s) {
        double largest = 0.0;
        for (int d = 0; d < kNumDofs; ++d) largest = std::max(largest, std::abs(steps_a[s][d] - steps_b[s][d]));
        EXPECT_GT(largest, 0.1) << Gestures()[a].name << " and " << Gestures()[b].name << " at step " << s;
      }
    }
  }
}

}  // namespace
}  // namespace nphand

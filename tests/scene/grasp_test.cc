#include "nphand/scene/grasp.h"

#include <cmath>
#include <set>

#include <algorithm>

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

TEST(GraspTest, TaxonomyHasThe33GraspsInOrder) {
  const auto& grasps = GraspTaxonomy();
  ASSERT_EQ(grasps.size(), static_cast<size_t>(kNumGrasps));
  std::set<std::string> names;
  for (size_t i = 0; i < grasps.size(); ++i) {
    EXPECT_EQ(grasps[i].id, i + 1);
    names.insert(GraspKey(grasps[i]));
    EXPECT_EQ(&GraspByName(grasps[i].name), &grasps[i]);
    EXPECT_FALSE(grasps[i].contacts.empty()) << grasps[i].name;
    EXPECT_FALSE(grasps[i].closing.empty()) << grasps[i].name;
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kNumGrasps));
  EXPECT_EQ(GraspByName("large_diameter").id, 1);
  EXPECT_THROW(GraspByName("juggle"), Error);
}

// The physical-consistency test of every grasp: the digits the taxonomy puts in contact
// touch the object (gap under 3 mm) and no vertex is inside it by more than 2 mm, at the
// final grasp; no step on the way penetrates more either.
class GraspConsistencyTest : public ::testing::TestWithParam<int> {};

TEST_P(GraspConsistencyTest, ContactsTouchAndNothingPenetrates) {
  const GraspDefinition& definition = GraspTaxonomy()[GetParam()];
  const Grasp grasp = MakeGrasp(RightHand(), definition);
  // The fingers start from the pre-shape or, where the object settled into their way, more
  // open (the same sign, no larger); only an opposed thumb may differ otherwise.
  for (int i = definition.oppose_thumb ? 5 : 0; i < kNumDofs; ++i) {
    const double defined = ClampToLimits(definition.preshape)[i], start = grasp.steps.front()[i];
    EXPECT_TRUE(start == defined || (start * defined >= 0.0 && std::abs(start) < std::abs(defined))) << Dofs()[i].name;
  }
  for (int k = 0; k < kGraspSteps; ++k) {
    HandPose pose;
    pose.angles = grasp.steps[k];
    ASSERT_TRUE(pose.IsValid()) << "step " << k;
    const GraspContact contact = MeasureContact(RightHand(), grasp.steps[k], grasp.object);
    EXPECT_LE(contact.penetration, 0.002) << definition.name << " step " << k;
    if (k + 1 < kGraspSteps) continue;
    for (Digit d : definition.contacts) {
      EXPECT_LT(contact.digit_gap[static_cast<int>(d)], 0.003) << definition.name << ": " << ToString(d);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllGrasps, GraspConsistencyTest, ::testing::Range(0, kNumGrasps),
                         [](const ::testing::TestParamInfo<int>& info) { return GraspKey(GraspTaxonomy()[info.param]); });

// A grasp definition is data a library user may write: impossible ones are errors, not aborts.
TEST(GraspTest, ImpossibleDefinitionsAreRefusedWithTheirName) {
  const auto opposed = std::find_if(GraspTaxonomy().begin(), GraspTaxonomy().end(),
                                    [](const GraspDefinition& g) { return g.oppose_thumb; });
  ASSERT_NE(opposed, GraspTaxonomy().end());
  GraspDefinition thumb_only = *opposed;
  thumb_only.name = "Thumb Only";
  thumb_only.contacts = {Digit::kThumb};
  testing::ExpectError([&] { MakeGrasp(RightHand(), thumb_only); }, "grasp Thumb Only: needs a contact finger");
  GraspDefinition huge = GraspTaxonomy()[0];
  huge.name = "Huge";
  huge.object.size[0] = 0.5;  // a cylinder half a metre in radius never clears the hand
  testing::ExpectError([&] { MakeGrasp(RightHand(), huge); }, "grasp Huge: the object cannot be moved clear");
}

TEST(GraspTest, MakeGraspIsDeterministic) {
  const Grasp a = MakeGrasp(RightHand(), GraspTaxonomy()[0]), b = MakeGrasp(RightHand(), GraspTaxonomy()[0]);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_TRUE(a.object.hand_from_object.isApprox(b.object.hand_from_object, 0.0));
}

}  // namespace
}  // namespace nphand

#include "nphand/util/progress.h"

#include <sstream>

#include <gtest/gtest.h>

namespace nphand {
namespace {

// A clock the test moves by hand.
std::chrono::steady_clock::time_point fake_now;
std::chrono::steady_clock::time_point FakeNow() { return fake_now; }

TEST(ProgressTest, ClockIsMinutesAndSeconds) {
  EXPECT_EQ(FormatClock(0), "0:00");
  EXPECT_EQ(FormatClock(59.6), "1:00");
  EXPECT_EQ(FormatClock(3725), "62:05");
  EXPECT_EQ(FormatClock(-4), "0:00");
}

TEST(ProgressTest, FirstAndLastUpdatesPrintAndFinishEndsTheLine) {
  std::ostringstream out;
  ProgressLine line(&out, "index build", 200, "entries", 0, &FakeNow);
  fake_now += std::chrono::seconds(2);
  line.Update(10);
  EXPECT_EQ(out.str(), "\rindex build: 10/200 entries (5%), 5/s, ETA 0:38   ");
  fake_now += std::chrono::milliseconds(900);
  line.Update(11);
  EXPECT_EQ(out.str().find("11/200"), std::string::npos) << "at most one line a second";
  fake_now += std::chrono::milliseconds(200);
  line.Update(12);
  EXPECT_NE(out.str().find("12/200"), std::string::npos) << "a second after the last line";
  line.Update(200);
  EXPECT_NE(out.str().find("200/200 entries (100%)"), std::string::npos) << "the last one always";
  EXPECT_NE(out.str().find("ETA 0:00"), std::string::npos);
  line.Finish();
  EXPECT_EQ(out.str().back(), '\n');
}

TEST(ProgressTest, ResumedWorkCountsTowardTheFractionOnly) {
  std::ostringstream out;
  ProgressLine line(&out, "db build", 100, "entries", 50);
  line.Update(50);
  EXPECT_NE(out.str().find("50/100 entries (50%), 0/s"), std::string::npos) << out.str();
}

TEST(ProgressTest, NoStreamNoOutputAndFinishWithoutALinePrintsNothing) {
  ProgressLine quiet(nullptr, "x", 10, "items");
  quiet.Update(10);
  quiet.Finish();
  std::ostringstream out;
  ProgressLine unused(&out, "x", 10, "items");
  unused.Finish();
  EXPECT_TRUE(out.str().empty());
}

}  // namespace
}  // namespace nphand

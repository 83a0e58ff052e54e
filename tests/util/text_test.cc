#include "nphand/util/text.h"

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(TextTest, ValidUtf8IsKept) {
  for (const std::string text : {"", "frame_001.png", "caf\xC3\xA9.jpg", "\xE6\x89\x8B.png", "\xF0\x9F\x96\x90.png"}) {
    EXPECT_EQ(Utf8OrEscaped(text), text);
  }
}

TEST(TextTest, BytesThatAreNotUtf8AreEscaped) {
  EXPECT_EQ(Utf8OrEscaped("caf\xE9.jpg"), "caf\\xE9.jpg") << "Latin-1";
  EXPECT_EQ(Utf8OrEscaped("\xC3"), "\\xC3") << "cut off";
  EXPECT_EQ(Utf8OrEscaped("\xC0\xAF"), "\\xC0\\xAF") << "overlong";
  EXPECT_EQ(Utf8OrEscaped("\xED\xA0\x80"), "\\xED\\xA0\\x80") << "a surrogate";
  EXPECT_EQ(Utf8OrEscaped("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80") << "above U+10FFFF";
  EXPECT_EQ(Utf8OrEscaped("a\xFF\xC3\xA9"), "a\\xFF\xC3\xA9") << "the valid part after a bad byte is kept";
}

}  // namespace
TEST(TextTest, AsciiLowerLowersCapitalsOnly) {
  EXPECT_EQ(AsciiLower("Clip.MP4"), "clip.mp4");
  EXPECT_EQ(AsciiLower("RIGHT"), "right");
  EXPECT_EQ(AsciiLower("caf\xC9.PNG"), "caf\xC9.png") << "bytes beyond ASCII are kept";
}

}  // namespace nphand

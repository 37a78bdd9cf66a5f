#include <gtest/gtest.h>

#include <string>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

TEST(ReadableMessage, ShortWordsStayWholeAndLongOnesKeepTheirStartAndEnd) {
  EXPECT_EQ(readable_message("set.csv:3: bad value \"x\""), "set.csv:3: bad value \"x\"");
  const std::string word = "\"" + std::string(1000, 'a') + "tail\"";
  const std::string shown = readable_message("bad value " + word + " given\ttwice");
  EXPECT_EQ(shown.substr(0, 12), "bad value \"a");
  EXPECT_NE(shown.find("...[" + std::to_string(word.size() - 160) + " characters cut]..."), std::string::npos) << shown;
  EXPECT_NE(shown.find("atail\" given\ttwice"), std::string::npos) << "the end and the spacing kept";
  EXPECT_LT(shown.size(), 220u);
  const std::string at_limit(kLongestWordShown, 'b');
  EXPECT_EQ(readable_message(at_limit), at_limit);
}

TEST(ReadableMessage, CutsOnlyBetweenCharacters) {
  // Two-byte characters (e with an acute accent): no cut splits one.
  std::string word;
  for (int i = 0; i < 300; ++i) word += "\xc3\xa9";
  const std::string shown = readable_message(word);
  const std::size_t cut = shown.find("...[");
  ASSERT_NE(cut, std::string::npos);
  EXPECT_EQ(cut % 2, 0u) << "the head ends on a character boundary";
  const std::size_t tail = shown.find("]...") + 4;
  EXPECT_EQ((shown.size() - tail) % 2, 0u) << "the tail starts on a character boundary";
  EXPECT_EQ(static_cast<unsigned char>(shown[tail]), 0xc3);
  EXPECT_NE(shown.find("...[220 characters cut]..."), std::string::npos) << "characters, not bytes: " << shown.substr(cut, 40);
}

}  // namespace
}  // namespace dicestack

// The access token of `octray view` (view/token.h).

#include "view/token.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace {

using octray::view::random_token;
using octray::view::tokens_equal;

TEST(ViewToken, Is128BitsAsLowercaseHex) {
    const std::string token = random_token();
    ASSERT_EQ(token.size(), 32u);
    EXPECT_EQ(token.find_first_not_of("0123456789abcdef"), std::string::npos) << token;
}

TEST(ViewToken, IsNewEachTime) {
    std::set<std::string> tokens;
    for (int i = 0; i < 64; ++i) tokens.insert(random_token());
    EXPECT_EQ(tokens.size(), 64u);
}

TEST(ViewToken, ComparesWholeStrings) {
    EXPECT_TRUE(tokens_equal("abc", "abc"));
    EXPECT_FALSE(tokens_equal("abc", "abd"));
    EXPECT_FALSE(tokens_equal("abc", "ab"));
    EXPECT_FALSE(tokens_equal("abc", ""));
    EXPECT_TRUE(tokens_equal("", ""));
}

}  // namespace

#include "lidar/util/named_choice.h"

#include <gtest/gtest.h>

namespace colmap_lidar {
namespace {

enum class Fruit { kApple, kPear, kPlum };
constexpr NamedChoices<Fruit, 4> kFruitNames = {{{"apple", Fruit::kApple},
                                                 {"pear", Fruit::kPear},
                                                 {"plum", Fruit::kPlum},
                                                 {"prune", Fruit::kPlum}}};

TEST(NamedChoiceTest, NamesAndValuesGoBothWays) {
  EXPECT_EQ(ChoiceFromName(kFruitNames, "pear", "fruit"), Fruit::kPear);
  EXPECT_EQ(ChoiceFromName(kFruitNames, "prune", "fruit"), Fruit::kPlum);
  EXPECT_STREQ(ChoiceName(kFruitNames, Fruit::kPlum), "plum");  // the first of its names
  EXPECT_EQ(ChoiceNames(kFruitNames), "apple, pear, plum or prune");
}

TEST(NamedChoiceTest, AnUnknownNameIsRefusedWithTheChoices) {
  try {
    ChoiceFromName(kFruitNames, "Pear", "fruit");
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "unknown fruit 'Pear' (expected apple, pear, plum or prune)");
  }
}

}  // namespace
}  // namespace colmap_lidar

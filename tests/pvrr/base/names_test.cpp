// Name tables (pvrr/base/names.h): lookups both ways, lists in the table's order, filters, unknown names.
#include <gtest/gtest.h>

#include "pvrr/base/names.h"

namespace pvrr {
namespace {

enum class Fruit { Apple, Blood_Orange, Pear };
constexpr NameTable<Fruit, 3> kFruitNames = {
    {{Fruit::Apple, "apple"}, {Fruit::Blood_Orange, "blood-orange"}, {Fruit::Pear, "pear"}}};
constexpr const NameTable<Fruit, 3>& nameTable(Fruit) { return kFruitNames; }
static_assert(namesAreUnique(kFruitNames));
static_assert(std::string_view(nameOf(Fruit::Pear)) == "pear", "nameOf is usable at compile time");

// A table listed in an order other than the enumerators'.
enum class Size { Small, Large, Medium };
constexpr NameTable<Size, 3> kSizeNames = {{{Size::Small, "small"}, {Size::Medium, "medium"}, {Size::Large, "large"}}};
constexpr const NameTable<Size, 3>& nameTable(Size) { return kSizeNames; }

TEST(Names, EveryValueRoundTrips) {
  for (const auto& entry : kFruitNames) {
    EXPECT_STREQ(nameOf(entry.value), entry.name);
    EXPECT_EQ(parseName<Fruit>(entry.name), entry.value) << entry.name;
  }
}

TEST(Names, UnknownNamesAreNotParsed) {
  EXPECT_EQ(parseName<Fruit>("banana"), std::nullopt);
  EXPECT_EQ(parseName<Fruit>(""), std::nullopt);
  EXPECT_EQ(parseName<Fruit>("Apple"), std::nullopt);   // exact case
  EXPECT_EQ(parseName<Fruit>("apple "), std::nullopt);  // exact word
  EXPECT_EQ(parseName<Fruit>("appl"), std::nullopt);
}

TEST(Names, AValueOutsideTheTableIsNamedQuestionMark) { EXPECT_STREQ(nameOf(static_cast<Fruit>(7)), "?"); }

TEST(Names, ListsFollowTheTablesOrder) {
  EXPECT_EQ(nameList<Fruit>(), "apple, blood-orange, pear");
  EXPECT_EQ(nameList<Fruit>(" | "), "apple | blood-orange | pear");
  EXPECT_EQ(nameList<Size>(), "small, medium, large");
  EXPECT_EQ(nameVector<Size>(), (std::vector<std::string>{"small", "medium", "large"}));
}

TEST(Names, FiltersKeepTheTablesOrder) {
  const auto not_medium = [](Size s) { return s != Size::Medium; };
  EXPECT_EQ(nameListIf<Size>(not_medium), "small, large");
  EXPECT_EQ(nameVectorIf<Size>(not_medium), (std::vector<std::string>{"small", "large"}));
  EXPECT_EQ(nameListIf<Size>([](Size) { return false; }), "");
}

TEST(Names, DuplicateValuesOrNamesAreFound) {
  constexpr NameTable<Fruit, 2> same_value = {{{Fruit::Apple, "apple"}, {Fruit::Apple, "pear"}}};
  constexpr NameTable<Fruit, 2> same_name = {{{Fruit::Apple, "apple"}, {Fruit::Pear, "apple"}}};
  static_assert(!namesAreUnique(same_value));
  static_assert(!namesAreUnique(same_name));
  EXPECT_TRUE(namesAreUnique(kSizeNames));
}

}  // namespace
}  // namespace pvrr

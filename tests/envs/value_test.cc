#include "pixelgym/envs/value.h"

#include <gtest/gtest.h>

namespace pixelgym {
namespace {

TEST(ValueTest, DictKeepsInsertionOrderAndReplacesInPlace) {
  ValueDict dict;
  dict.insert("pixels", Array(DType::kUInt8, {2, 2, 3}));
  dict.insert("joint_pos", Array(DType::kFloat32, {2}));
  dict.insert("pixels", Array(DType::kUInt8, {4, 4, 3}));
  EXPECT_EQ(dict.keys(), (std::vector<std::string>{"pixels", "joint_pos"}));
  EXPECT_EQ(dict.at("pixels").array().shape(), (Shape{4, 4, 3}));
}

TEST(ValueTest, MissingKeyNamesKeysPresent) {
  ValueDict dict{{"a", Array::scalar(1.0)}};
  try {
    dict.at("b");
    FAIL();
  } catch (const std::out_of_range& error) {
    EXPECT_NE(std::string(error.what()).find("\"a\""), std::string::npos);
  }
}

TEST(ValueTest, WrongAlternativeThrows) {
  Value value = Array::scalar(1.0);
  EXPECT_TRUE(value.is_array());
  EXPECT_THROW(value.dict(), std::invalid_argument);
  EXPECT_THROW(value.tuple(), std::invalid_argument);
}

TEST(ValueTest, CloneIsDeepAndEqual) {
  Value value = ValueDict{{"x", Array::from_vector<float>({2}, {1, 2})},
                          {"t", ValueTuple{Array::scalar<std::int64_t>(3)}}};
  Value copy = value.clone();
  EXPECT_TRUE(copy.equals(value));
  EXPECT_FALSE(copy.shares_memory(value));
  Value shallow = value;
  EXPECT_TRUE(shallow.shares_memory(value));
  copy.dict().at("x").array().data<float>()[0] = 9;
  EXPECT_FALSE(copy.equals(value));
}

TEST(ValueTest, EqualsComparesStructure) {
  Value a = ValueTuple{Array::scalar(1.0)};
  Value b = ValueTuple{Array::scalar(1.0), Array::scalar(1.0)};
  Value c = ValueDict{{"x", Array::scalar(1.0)}};
  EXPECT_FALSE(a.equals(b));
  EXPECT_FALSE(a.equals(c));
  EXPECT_FALSE(c.equals(Value(ValueDict{{"y", Array::scalar(1.0)}})));
}

TEST(ValueTest, LeavesAreDepthFirst) {
  Value value = ValueDict{{"a", Array::scalar(1.0)},
                          {"b", ValueTuple{Array::scalar(2.0), Array::scalar(3.0)}}};
  const std::vector<Array> leaves = value.leaves();
  ASSERT_EQ(leaves.size(), 3U);
  EXPECT_EQ(leaves[2].item<double>(), 3.0);
}

TEST(ValueTest, ToString) {
  Value value = ValueDict{{"a", Array::scalar<std::int64_t>(1)}};
  EXPECT_EQ(value.to_string(), "Dict{\"a\": int64 () 1}");
}

TEST(ValueTest, DictEraseAndClear) {
  ValueDict dict{{"a", Array::scalar(1.0)}, {"b", Array::scalar(2.0)}, {"c", Array::scalar(3.0)}};
  dict.erase("b");
  EXPECT_EQ(dict.keys(), (std::vector<std::string>{"a", "c"}));
  EXPECT_EQ(dict.at("c").array().item<double>(), 3.0);
  EXPECT_THROW(dict.erase("b"), std::out_of_range);
  dict.clear();
  EXPECT_TRUE(dict.empty());
  EXPECT_THROW(dict.at("a"), std::out_of_range);
}
}  // namespace
}  // namespace pixelgym

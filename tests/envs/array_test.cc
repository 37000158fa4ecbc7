#include "pixelgym/envs/array.h"

#include <gtest/gtest.h>

namespace pixelgym {
namespace {

TEST(ArrayTest, NewArrayIsZeroFilledWithShapeAndDtype) {
  Array array(DType::kFloat32, {2, 3});
  EXPECT_EQ(array.dtype(), DType::kFloat32);
  EXPECT_EQ(array.shape(), (Shape{2, 3}));
  EXPECT_EQ(array.ndim(), 2);
  EXPECT_EQ(array.size(), 6);
  EXPECT_EQ(array.nbytes(), 24U);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(array.data<float>()[i], 0.0F);
}

TEST(ArrayTest, CopyIsShallowAndSharesMemory) {
  Array a = Array::from_vector<std::int32_t>({3}, {1, 2, 3});
  Array b = a;  // NOLINT(performance-unnecessary-copy-initialization): the copy is the point
  b.data<std::int32_t>()[0] = 42;
  EXPECT_EQ(a.data<std::int32_t>()[0], 42);
  EXPECT_TRUE(a.shares_memory(b));
}

TEST(ArrayTest, CloneIsDeepAndIndependent) {
  Array a = Array::from_vector<std::int32_t>({3}, {1, 2, 3});
  Array c = a.clone();
  EXPECT_TRUE(c.equals(a));
  EXPECT_FALSE(c.shares_memory(a));
  c.data<std::int32_t>()[0] = 42;
  EXPECT_EQ(a.data<std::int32_t>()[0], 1);
  EXPECT_FALSE(c.equals(a));
}

TEST(ArrayTest, MemoryOutlivesTheArrayThatAllocatedIt) {
  Array view;
  {
    Array owner = Array::from_vector<double>({2, 2}, {1, 2, 3, 4});
    view = owner.index(1);
  }
  EXPECT_EQ(view.shape(), (Shape{2}));
  EXPECT_EQ(view.data<double>()[0], 3.0);
  EXPECT_EQ(view.data<double>()[1], 4.0);
}

TEST(ArrayTest, IndexAndReshapeAreViews) {
  Array a = Array::from_vector<std::uint8_t>({2, 3}, {0, 1, 2, 3, 4, 5});
  Array row = a.index(1);
  EXPECT_TRUE(row.shares_memory(a));
  row.data<std::uint8_t>()[2] = 99;
  EXPECT_EQ(a.data<std::uint8_t>()[5], 99);
  Array flat = a.reshape({6});
  EXPECT_EQ(flat.shape(), (Shape{6}));
  EXPECT_TRUE(flat.shares_memory(a));
  EXPECT_THROW(a.reshape({4}), std::invalid_argument);
  EXPECT_THROW(a.index(2), std::out_of_range);
  EXPECT_THROW(a.index(-1), std::out_of_range);
  EXPECT_THROW(Array::scalar(1.0).index(0), std::out_of_range);
}

TEST(ArrayTest, WrongDtypeAccessThrowsNamingBoth) {
  Array a(DType::kUInt8, {2});
  try {
    a.data<float>();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("float32"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("uint8"), std::string::npos);
  }
}

TEST(ArrayTest, ScalarAndItem) {
  Array s = Array::scalar<std::int64_t>(7);
  EXPECT_EQ(s.ndim(), 0);
  EXPECT_EQ(s.size(), 1);
  EXPECT_EQ(s.item<std::int64_t>(), 7);
  EXPECT_THROW(Array(DType::kInt64, {2}).item<std::int64_t>(), std::invalid_argument);
  EXPECT_EQ(Array::scalar(true).dtype(), DType::kBool);
}

TEST(ArrayTest, FromVectorChecksCount) {
  EXPECT_THROW(Array::from_vector<float>({2, 2}, {1, 2, 3}), std::invalid_argument);
}

TEST(ArrayTest, NegativeExtentThrows) {
  EXPECT_THROW(Array(DType::kFloat32, {2, -1}), std::invalid_argument);
}

TEST(ArrayTest, EqualsComparesDtypeShapeAndBytes) {
  Array a = Array::from_vector<float>({2}, {1, 2});
  EXPECT_TRUE(a.equals(Array::from_vector<float>({2}, {1, 2})));
  EXPECT_FALSE(a.equals(Array::from_vector<float>({2}, {1, 3})));
  EXPECT_FALSE(a.equals(Array::from_vector<double>({2}, {1, 2})));
  EXPECT_FALSE(a.equals(Array::from_vector<float>({2, 1}, {1, 2})));
}

TEST(ArrayTest, CopyFromChecksDtypeAndShape) {
  Array target(DType::kFloat32, {2});
  target.copy_from(Array::from_vector<float>({2}, {5, 6}));
  EXPECT_EQ(target.data<float>()[1], 6.0F);
  EXPECT_THROW(target.copy_from(Array::from_vector<double>({2}, {5, 6})), std::invalid_argument);
  EXPECT_THROW(target.copy_from(Array::from_vector<float>({3}, {5, 6, 7})), std::invalid_argument);
}

TEST(ArrayTest, FromExternalKeepsOwnerAlive) {
  auto owner = std::make_shared<std::vector<float>>(std::vector<float>{1.5F, 2.5F});
  std::weak_ptr<std::vector<float>> watch = owner;
  Array view = Array::from_external(owner->data(), DType::kFloat32, {2}, owner);
  owner.reset();
  EXPECT_FALSE(watch.expired());
  EXPECT_EQ(view.data<float>()[1], 2.5F);
  view = Array();
  EXPECT_TRUE(watch.expired());
}

TEST(ArrayTest, ToStringShowsDtypeShapeAndSmallValues) {
  EXPECT_EQ(Array::scalar<std::int64_t>(3).to_string(), "int64 () 3");
  EXPECT_EQ(Array::from_vector<float>({2}, {0.5F, -1.0F}).to_string(), "float32 (2,) [0.5, -1]");
  EXPECT_EQ(Array(DType::kUInt8, {84, 84, 3}).to_string(), "uint8 (84, 84, 3)");
}

TEST(ArrayTest, SliceViewsRowsOfTheLeadingAxis) {
  Array batch = Array::from_vector<std::int32_t>({4, 2}, {0, 1, 2, 3, 4, 5, 6, 7});
  Array middle = batch.slice(1, 3);
  EXPECT_EQ(middle.shape(), (Shape{2, 2}));
  EXPECT_TRUE(middle.shares_memory(batch));
  EXPECT_EQ(middle.data<std::int32_t>()[0], 2);
  EXPECT_EQ(middle.data<std::int32_t>()[3], 5);
  middle.data<std::int32_t>()[0] = 20;  // writes through to the batch
  EXPECT_EQ(batch.data<std::int32_t>()[2], 20);
  EXPECT_EQ(batch.slice(4, 4).shape(), (Shape{0, 2}));
  EXPECT_EQ(batch.slice(0, 4).data<std::int32_t>(), batch.data<std::int32_t>());
  // A slot of a slice is the batch's slot.
  EXPECT_EQ(middle.index(1).data<std::int32_t>(), batch.index(2).data<std::int32_t>());
  EXPECT_THROW(batch.slice(3, 2), std::out_of_range);
  EXPECT_THROW(batch.slice(-1, 2), std::out_of_range);
  EXPECT_THROW(batch.slice(0, 5), std::out_of_range);
  EXPECT_THROW(Array::scalar(1.0F).slice(0, 0), std::out_of_range);
}
}  // namespace
}  // namespace pixelgym

// The messages between the ranks of a distributed run (core/byte_buffer.h).
#include "core/byte_buffer.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace texlume {
namespace {

TEST(ByteBuffer, ValuesVectorsAndMatricesRoundTrip) {
  cv::Mat grid(3, 5, CV_32FC3);
  cv::randu(grid, -1.0, 1.0);
  const cv::Mat roi =
      cv::Mat(cv::Mat::eye(6, 6, CV_64FC1))(cv::Rect(1, 1, 3, 4));  // not continuous
  ByteWriter out;
  out.Put<std::int32_t>(-7);
  out.Put(2.5);
  out.PutVector(std::vector<std::array<double, 3>>{{1, 2, 3}, {4, 5, 6}});
  out.PutMats({grid, cv::Mat(), roi});
  ByteReader in(out.bytes());
  EXPECT_EQ(in.Get<std::int32_t>(), -7);
  EXPECT_EQ(in.Get<double>(), 2.5);
  const auto v = in.GetVector<std::array<double, 3>>();
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1][2], 6.0);
  const std::vector<cv::Mat> mats = in.GetMats();
  ASSERT_EQ(mats.size(), 3u);
  EXPECT_EQ(cv::norm(mats[0], grid, cv::NORM_INF), 0.0);
  EXPECT_TRUE(mats[1].empty());
  EXPECT_EQ(mats[2].type(), CV_64FC1);
  EXPECT_EQ(cv::norm(mats[2], roi, cv::NORM_INF), 0.0);
  EXPECT_EQ(in.Remaining(), 0u);
}

TEST(ByteBuffer, ReadingPastTheEndIsAnInternalError) {
  ByteWriter out;
  out.PutVector(std::vector<float>(4, 1.0f));
  std::vector<char> cut = out.bytes();
  cut.resize(cut.size() - 1);
  ByteReader in(cut);
  EXPECT_THROW(in.GetVector<float>(), InternalError);
  ByteWriter huge;
  huge.Put<std::int32_t>(CV_32FC1), huge.Put<std::int32_t>(1 << 20),
      huge.Put<std::int32_t>(1 << 20);
  ByteReader mat(huge.bytes());
  EXPECT_THROW(mat.GetMat(), InternalError);
}

}  // namespace
}  // namespace texlume

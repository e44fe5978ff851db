#include "model/web_model.h"

#include <gtest/gtest.h>

namespace texlume::model {
namespace {

TEST(QuantisePlane, ConstantPlanesAndExtremesAreExact) {
  const QuantisedPlane constant = QuantisePlane({0.25f, 0.25f});
  EXPECT_EQ(constant.bias, 0.25f);
  EXPECT_EQ(constant.bytes[0], 0);
  const QuantisedPlane q = QuantisePlane({-1.0f, 0.5f, 3.0f});
  EXPECT_EQ(q.bytes[0], 0);
  EXPECT_EQ(q.bytes[2], 255);
  EXPECT_NEAR(q.bytes[1] / 255.0 * q.scale + q.bias, 0.5, 0.5 * q.scale / 255.0);
}

}  // namespace
}  // namespace texlume::model

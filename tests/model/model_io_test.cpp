#include "model/model_io.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace texlume::model {
namespace {

TEST(LightResponseJson, RoundTripsAndRefusesMalformedRecordsNamingTheFile) {
  ptm::LightResponse r;
  for (std::size_t k = 0; k < r.elevation_factor.size(); ++k)
    r.elevation_factor[k] = 0.7 + 0.05 * static_cast<double>(k);
  r.ambient = 0.021;
  const nlohmann::json record = LightResponseJson(r);
  EXPECT_EQ(record["elevations_deg"][3].get<double>(), 30.0);
  const ptm::LightResponse back = LightResponseFromJson(record, "m/manifest.json");
  EXPECT_EQ(back.elevation_factor, r.elevation_factor);
  EXPECT_EQ(back.ambient, r.ambient);

  nlohmann::json short_factors = record;
  short_factors["factors"].erase(0);
  nlohmann::json negative = record;
  negative["factors"][2] = -1.0;
  nlohmann::json moved_knot = record;
  moved_knot["elevations_deg"][1] = 12.0;
  nlohmann::json no_ambient = record;
  no_ambient.erase("ambient");
  for (const nlohmann::json& bad : {short_factors, negative, moved_knot, no_ambient,
                                    nlohmann::json(), nlohmann::json::array()}) {
    try {
      LightResponseFromJson(bad, "m/manifest.json");
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("m/manifest.json"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace texlume::model

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/semantic_classes.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

// The built-in table must agree with the official semantic-kitti.yaml.
TEST(SemanticClasses, MatchesOfficialYaml) {
  SALOAM_REQUIRE_SHARED_DATA();
  const YAML::Node yaml = YAML::LoadFile(testing::shared_file("data/semantic-kitti.yaml").string());
  const YAML::Node labels = yaml["labels"];
  ASSERT_TRUE(labels.IsMap());
  EXPECT_EQ(semantic_kitti_classes().size(), labels.size());
  for (const auto& entry : labels) {
    const auto id = entry.first.as<std::uint16_t>();
    const auto cls = find_semantic_class(id);
    ASSERT_TRUE(cls.has_value()) << id;
    EXPECT_EQ(cls->name, entry.second.as<std::string>());
    const auto bgr = yaml["color_map"][id];
    EXPECT_EQ(cls->color, (Rgb{bgr[2].as<std::uint8_t>(), bgr[1].as<std::uint8_t>(), bgr[0].as<std::uint8_t>()}))
        << cls->name;
    EXPECT_EQ(to_learning_class(id), yaml["learning_map"][id].as<int>()) << cls->name;
  }
  for (const auto& entry : yaml["learning_map_inv"]) {
    EXPECT_EQ(from_learning_class(entry.first.as<std::uint8_t>()), entry.second.as<std::uint16_t>());
  }
}

TEST(SemanticClasses, DynamicAndStatic) {
  EXPECT_TRUE(is_dynamic(cls::kMovingCar));
  EXPECT_TRUE(is_dynamic(cls::kPerson));
  EXPECT_TRUE(is_dynamic(cls::kBicyclist));
  EXPECT_FALSE(is_dynamic(cls::kCar));
  EXPECT_FALSE(is_dynamic(cls::kBuilding));
  EXPECT_TRUE(is_moving(cls::kMovingPerson));
  EXPECT_FALSE(is_moving(cls::kPerson));
  EXPECT_EQ(static_class(cls::kMovingCar), cls::kCar);
  EXPECT_EQ(static_class(cls::kMovingTruck), cls::kTruck);
  EXPECT_EQ(static_class(cls::kPole), cls::kPole);
  EXPECT_TRUE(is_ground(cls::kRoad));
  EXPECT_TRUE(is_ground(cls::kTerrain));
  EXPECT_FALSE(is_ground(cls::kBuilding));
}

TEST(SemanticClasses, UnknownIdsAreSafe) {
  EXPECT_FALSE(find_semantic_class(5).has_value());
  EXPECT_FALSE(find_semantic_class(60000).has_value());
  EXPECT_EQ(class_name(60000), "unknown");
  EXPECT_EQ(to_learning_class(60000), 0);
  EXPECT_EQ(class_color(7), (Rgb{0, 0, 0}));
  EXPECT_EQ(semantic_class_id("traffic-sign"), cls::kTrafficSign);
  EXPECT_FALSE(semantic_class_id("spaceship").has_value());
  EXPECT_EQ(learning_class_name(19), "traffic-sign");
}

}  // namespace
}  // namespace saloam

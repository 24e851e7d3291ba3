#include "saloam/core/semantic_classes.hpp"

#include <algorithm>
#include <array>

namespace saloam {
namespace {

// Colours converted from the official BGR color_map to RGB.
constexpr std::array<SemanticClass, 34> kClasses{{
    {0, "unlabeled", {0, 0, 0}, 0, false},
    {1, "outlier", {255, 0, 0}, 0, false},
    {10, "car", {100, 150, 245}, 1, false},
    {11, "bicycle", {100, 230, 245}, 2, false},
    {13, "bus", {100, 80, 250}, 5, false},
    {15, "motorcycle", {30, 60, 150}, 3, false},
    {16, "on-rails", {0, 0, 255}, 5, false},
    {18, "truck", {80, 30, 180}, 4, false},
    {20, "other-vehicle", {0, 0, 255}, 5, false},
    {30, "person", {255, 30, 30}, 6, false},
    {31, "bicyclist", {255, 40, 200}, 7, false},
    {32, "motorcyclist", {150, 30, 90}, 8, false},
    {40, "road", {255, 0, 255}, 9, false},
    {44, "parking", {255, 150, 255}, 10, false},
    {48, "sidewalk", {75, 0, 75}, 11, false},
    {49, "other-ground", {175, 0, 75}, 12, false},
    {50, "building", {255, 200, 0}, 13, false},
    {51, "fence", {255, 120, 50}, 14, false},
    {52, "other-structure", {255, 150, 0}, 0, false},
    {60, "lane-marking", {150, 255, 170}, 9, false},
    {70, "vegetation", {0, 175, 0}, 15, false},
    {71, "trunk", {135, 60, 0}, 16, false},
    {72, "terrain", {150, 240, 80}, 17, false},
    {80, "pole", {255, 240, 150}, 18, false},
    {81, "traffic-sign", {255, 0, 0}, 19, false},
    {99, "other-object", {50, 255, 255}, 0, false},
    {252, "moving-car", {100, 150, 245}, 1, true},
    {253, "moving-bicyclist", {255, 40, 200}, 7, true},
    {254, "moving-person", {255, 30, 30}, 6, true},
    {255, "moving-motorcyclist", {150, 30, 90}, 8, true},
    {256, "moving-on-rails", {0, 0, 255}, 5, true},
    {257, "moving-bus", {100, 80, 250}, 5, true},
    {258, "moving-truck", {80, 30, 180}, 4, true},
    {259, "moving-other-vehicle", {0, 0, 255}, 5, true},
}};

constexpr std::array<std::uint16_t, kNumLearningClasses> kLearningToRaw{
    0, 10, 11, 15, 18, 20, 30, 31, 32, 40, 44, 48, 49, 50, 51, 70, 71, 72, 80, 81};

// Dense lookup from raw id to table index (ids go up to 259).
struct Index {
  std::array<std::int8_t, 260> slot{};
  constexpr Index() {
    for (auto& s : slot) s = -1;
    for (std::size_t i = 0; i < kClasses.size(); ++i) slot[kClasses[i].id] = static_cast<std::int8_t>(i);
  }
};
constexpr Index kIndex;

const SemanticClass* lookup(std::uint16_t raw_id) {
  if (raw_id >= kIndex.slot.size() || kIndex.slot[raw_id] < 0) return nullptr;
  return &kClasses[static_cast<std::size_t>(kIndex.slot[raw_id])];
}

}  // namespace

std::span<const SemanticClass> semantic_kitti_classes() { return kClasses; }

std::optional<SemanticClass> find_semantic_class(std::uint16_t raw_id) {
  if (const auto* c = lookup(raw_id)) return *c;
  return std::nullopt;
}

std::optional<std::uint16_t> semantic_class_id(std::string_view name) {
  const auto it = std::find_if(kClasses.begin(), kClasses.end(),
                               [&](const SemanticClass& c) { return c.name == name; });
  if (it == kClasses.end()) return std::nullopt;
  return it->id;
}

std::string_view class_name(std::uint16_t raw_id) {
  const auto* c = lookup(raw_id);
  return c ? c->name : std::string_view{"unknown"};
}

Rgb class_color(std::uint16_t raw_id) {
  const auto* c = lookup(raw_id);
  return c ? c->color : Rgb{};
}

std::uint8_t to_learning_class(std::uint16_t raw_id) {
  const auto* c = lookup(raw_id);
  return c ? c->learning : 0;
}

std::uint16_t from_learning_class(std::uint8_t learning_id) {
  return learning_id < kLearningToRaw.size() ? kLearningToRaw[learning_id] : 0;
}

std::string_view learning_class_name(std::uint8_t learning_id) {
  return class_name(from_learning_class(learning_id));
}

std::optional<std::uint8_t> learning_class_id(std::string_view name) {
  for (int c = 1; c < kNumLearningClasses; ++c)
    if (learning_class_name(static_cast<std::uint8_t>(c)) == name) return static_cast<std::uint8_t>(c);
  return std::nullopt;
}

bool is_moving(std::uint16_t raw_id) {
  const auto* c = lookup(raw_id);
  return c != nullptr && c->moving;
}

bool is_dynamic(std::uint16_t raw_id) {
  return is_moving(raw_id) || raw_id == cls::kPerson || raw_id == cls::kBicyclist ||
         raw_id == cls::kMotorcyclist;
}

std::uint16_t static_class(std::uint16_t raw_id) {
  switch (raw_id) {
    case cls::kMovingCar: return cls::kCar;
    case cls::kMovingBicyclist: return cls::kBicyclist;
    case cls::kMovingPerson: return cls::kPerson;
    case cls::kMovingMotorcyclist: return cls::kMotorcyclist;
    case cls::kMovingOnRails: return cls::kOnRails;
    case cls::kMovingBus: return cls::kBus;
    case cls::kMovingTruck: return cls::kTruck;
    case cls::kMovingOtherVehicle: return cls::kOtherVehicle;
    default: return raw_id;
  }
}

bool is_ground(std::uint16_t raw_id) {
  switch (raw_id) {
    case cls::kRoad:
    case cls::kParking:
    case cls::kSidewalk:
    case cls::kOtherGround:
    case cls::kLaneMarking:
    case cls::kTerrain: return true;
    default: return false;
  }
}

}  // namespace saloam

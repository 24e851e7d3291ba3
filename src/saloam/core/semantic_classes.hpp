#pragma once
// The SemanticKITTI class table, built into the library: raw class ids,
// names, colours, the learning map to the 19 training classes, and which
// classes move. Source: semantic-kitti-api config (MIT, University of Bonn).

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace saloam {

/// Raw SemanticKITTI class ids (the low 16 bits of a .label entry).
namespace cls {
inline constexpr std::uint16_t kUnlabeled = 0;
inline constexpr std::uint16_t kOutlier = 1;
inline constexpr std::uint16_t kCar = 10;
inline constexpr std::uint16_t kBicycle = 11;
inline constexpr std::uint16_t kBus = 13;
inline constexpr std::uint16_t kMotorcycle = 15;
inline constexpr std::uint16_t kOnRails = 16;
inline constexpr std::uint16_t kTruck = 18;
inline constexpr std::uint16_t kOtherVehicle = 20;
inline constexpr std::uint16_t kPerson = 30;
inline constexpr std::uint16_t kBicyclist = 31;
inline constexpr std::uint16_t kMotorcyclist = 32;
inline constexpr std::uint16_t kRoad = 40;
inline constexpr std::uint16_t kParking = 44;
inline constexpr std::uint16_t kSidewalk = 48;
inline constexpr std::uint16_t kOtherGround = 49;
inline constexpr std::uint16_t kBuilding = 50;
inline constexpr std::uint16_t kFence = 51;
inline constexpr std::uint16_t kOtherStructure = 52;
inline constexpr std::uint16_t kLaneMarking = 60;
inline constexpr std::uint16_t kVegetation = 70;
inline constexpr std::uint16_t kTrunk = 71;
inline constexpr std::uint16_t kTerrain = 72;
inline constexpr std::uint16_t kPole = 80;
inline constexpr std::uint16_t kTrafficSign = 81;
inline constexpr std::uint16_t kOtherObject = 99;
inline constexpr std::uint16_t kMovingCar = 252;
inline constexpr std::uint16_t kMovingBicyclist = 253;
inline constexpr std::uint16_t kMovingPerson = 254;
inline constexpr std::uint16_t kMovingMotorcyclist = 255;
inline constexpr std::uint16_t kMovingOnRails = 256;
inline constexpr std::uint16_t kMovingBus = 257;
inline constexpr std::uint16_t kMovingTruck = 258;
inline constexpr std::uint16_t kMovingOtherVehicle = 259;
}  // namespace cls

/// Number of training classes including 0 = unlabeled/ignored (SemanticKITTI uses 0..19).
inline constexpr int kNumLearningClasses = 20;

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

struct SemanticClass {
  std::uint16_t id;         ///< raw SemanticKITTI id
  std::string_view name;    ///< e.g. "moving-car"
  Rgb color;                ///< official colour (the YAML stores BGR; this is RGB)
  std::uint8_t learning;    ///< training class 0..19 (0 = ignored)
  bool moving;              ///< a moving-* class
};

/// All 34 raw classes, sorted by id.
std::span<const SemanticClass> semantic_kitti_classes();

/// The table entry of a raw id, or nullopt for an id SemanticKITTI does not define.
std::optional<SemanticClass> find_semantic_class(std::uint16_t raw_id);
/// Raw id from a class name ("car", "moving-person", ...).
std::optional<std::uint16_t> semantic_class_id(std::string_view name);

/// Name of a raw id; "unknown" for ids outside the table.
std::string_view class_name(std::uint16_t raw_id);
/// Colour of a raw id; black for unknown ids.
Rgb class_color(std::uint16_t raw_id);

/// Learning map: raw id -> training class 0..19 (unknown ids map to 0).
std::uint8_t to_learning_class(std::uint16_t raw_id);
/// Inverse learning map: training class -> representative raw id.
std::uint16_t from_learning_class(std::uint8_t learning_id);
/// Name of a training class ("unlabeled", "car", ..., "traffic-sign").
std::string_view learning_class_name(std::uint8_t learning_id);
/// The training class 1..19 of that name, none for another name.
std::optional<std::uint8_t> learning_class_id(std::string_view name);

/// A moving-* class (252..259).
bool is_moving(std::uint16_t raw_id);
/// Classes that move or may move between scans and must not anchor
/// registration: moving-*, person, bicyclist, motorcyclist.
bool is_dynamic(std::uint16_t raw_id);
/// Maps moving-* to its static class (moving-car -> car); other ids unchanged.
std::uint16_t static_class(std::uint16_t raw_id);
/// Ground classes: road, parking, sidewalk, other-ground, lane-marking, terrain.
bool is_ground(std::uint16_t raw_id);

}  // namespace saloam

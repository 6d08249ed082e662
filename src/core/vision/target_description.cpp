// Kalibr target YAML parsing and the target's feature points.
#include "camera_imu_alignment/vision/target_description.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "camera_imu_alignment/common/input_error.h"

namespace camera_imu_alignment {

int TargetDescription::numPoints() const {
  return type == Type::kAprilGrid ? 4 * cols * rows : cols * rows;
}

Eigen::Vector3d TargetDescription::point(int index) const {
  if (type == Type::kAprilGrid) {
    // Kalibr's (2 tagRows) x (2 tagCols) corner grid, row-major from the lower left.
    const int grid_cols = 2 * cols;
    const int r = index / grid_cols, c = index % grid_cols;
    const double pitch = tag_size_m * (1.0 + tag_spacing);
    return {(c / 2) * pitch + (c % 2) * tag_size_m, (r / 2) * pitch + (r % 2) * tag_size_m, 0.0};
  }
  const int r = index / cols, c = index % cols;
  if (type == Type::kCircleGrid && asymmetric) {
    return {(2 * c + r % 2) * col_spacing_m, r * row_spacing_m, 0.0};
  }
  return {c * col_spacing_m, r * row_spacing_m, 0.0};
}

std::string TargetDescription::describe() const {
  std::ostringstream out;
  switch (type) {
    case Type::kCheckerboard:
      out << "checkerboard " << cols << "x" << rows << " inner corners, " << col_spacing_m << " m";
      break;
    case Type::kAprilGrid:
      out << "aprilgrid " << cols << "x" << rows << " tags, " << tag_size_m << " m";
      break;
    case Type::kCircleGrid:
      out << (asymmetric ? "asymmetric " : "") << "circlegrid " << cols << "x" << rows << ", "
          << col_spacing_m << " m";
      break;
  }
  return out.str();
}

namespace {

YAML::Node required(const YAML::Node& root, const std::string& key, const std::string& source) {
  const YAML::Node node = root[key];
  if (!node) throw InputError(source + ": key '" + key + "' missing");
  return node;
}

int positiveInt(const YAML::Node& root, const std::string& key, const std::string& source) {
  int value = 0;
  try {
    value = required(root, key, source).as<int>();
  } catch (const YAML::Exception&) {
    throw InputError(source + ": '" + key + "' is not an integer");
  }
  if (value <= 0) throw InputError(source + ": '" + key + "' must be positive");
  return value;
}

double positiveDouble(const YAML::Node& root, const std::string& key, const std::string& source,
                      bool allow_zero = false) {
  double value = 0.0;
  try {
    value = required(root, key, source).as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(source + ": '" + key + "' is not a number");
  }
  if (!std::isfinite(value) || value < 0.0 || (!allow_zero && value == 0.0)) {
    throw InputError(source + ": '" + key + "' must be " +
                     (allow_zero ? "non-negative" : "positive"));
  }
  return value;
}

}  // namespace

TargetDescription parseTargetYaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": not valid YAML (line " + std::to_string(e.mark.line + 1) +
                     "): " + e.msg);
  }
  if (!root.IsMap()) throw InputError(source + ": not a Kalibr target description (no mapping)");
  std::string type;
  try {
    type = required(root, "target_type", source).as<std::string>();
  } catch (const YAML::Exception&) {
    throw InputError(source + ": 'target_type' is not a string");
  }
  TargetDescription t;
  if (type == "checkerboard") {
    t.type = TargetDescription::Type::kCheckerboard;
    t.cols = positiveInt(root, "targetCols", source);
    t.rows = positiveInt(root, "targetRows", source);
    t.row_spacing_m = positiveDouble(root, "rowSpacingMeters", source);
    t.col_spacing_m = positiveDouble(root, "colSpacingMeters", source);
    if (t.cols < 2 || t.rows < 2)
      throw InputError(source + ": a checkerboard needs >= 2x2 corners");
  } else if (type == "aprilgrid") {
    t.type = TargetDescription::Type::kAprilGrid;
    t.cols = positiveInt(root, "tagCols", source);
    t.rows = positiveInt(root, "tagRows", source);
    t.tag_size_m = positiveDouble(root, "tagSize", source);
    t.tag_spacing = positiveDouble(root, "tagSpacing", source, true);
    if (t.cols * t.rows > 587) throw InputError(source + ": tag36h11 has only 587 tags");
  } else if (type == "circlegrid") {
    t.type = TargetDescription::Type::kCircleGrid;
    t.cols = positiveInt(root, "targetCols", source);
    t.rows = positiveInt(root, "targetRows", source);
    t.row_spacing_m = t.col_spacing_m = positiveDouble(root, "spacingMeters", source);
    if (root["asymmetricGrid"]) {
      try {
        t.asymmetric = root["asymmetricGrid"].as<bool>();
      } catch (const YAML::Exception&) {
        throw InputError(source + ": 'asymmetricGrid' is not a boolean");
      }
    }
  } else {
    throw InputError(source + ": unknown target_type '" + type +
                     "' (checkerboard, aprilgrid or circlegrid)");
  }
  return t;
}

TargetDescription loadTargetYaml(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open the target file");
  std::ostringstream text;
  text << file.rdbuf();
  return parseTargetYaml(text.str(), path);
}

}  // namespace camera_imu_alignment
